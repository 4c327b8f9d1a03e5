#include "src/imaging/oiio/oiio_status.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <system_error>
#include <vector>

namespace nave::imaging::oiio {

Status OiioError(const std::filesystem::path& file, std::string_view what,
                 std::string oiio_message) {
    std::error_code ec;
    // OIIO reports one failure on several lines (the reader's message, then the cache's wrapper
    // repeating it); nave's error is one line: a missing file says so, other failures keep OIIO's
    // distinct lines joined by "; ".
    if (!std::filesystem::exists(file, ec))
        return NotFoundError("{}: {}: no such file", file.string(), what);
    std::vector<std::string> lines;
    size_t pos = 0;
    while (pos < oiio_message.size()) {
        size_t end = oiio_message.find('\n', pos);
        if (end == std::string::npos) end = oiio_message.size();
        std::string line = oiio_message.substr(pos, end - pos);
        while (!line.empty() && line.back() == ' ') line.pop_back();
        if (!line.empty() && std::find(lines.begin(), lines.end(), line) == lines.end())
            lines.push_back(std::move(line));
        pos = end + 1;
    }
    std::string detail;
    for (const std::string& l : lines) detail += (detail.empty() ? "" : "; ") + l;
    if (detail.empty()) detail = "no detail from OpenImageIO";
    return IoError("{}: {}: {}", file.string(), what, detail);
}

std::string TakeError(OIIO::TextureSystem& ts) {
    std::string e = ts.geterror();
    if (e.empty()) e = OIIO::geterror();
    return e;
}

}  // namespace nave::imaging::oiio
