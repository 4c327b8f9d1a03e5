// End-to-end: what `nave render` prints at the end agrees with the statistics it writes into the
// EXR's metadata, in-core and under --memory.

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <sstream>

#include "common/run_nave.h"
#include "src/core/memory.h"
#include "src/core/progress.h"

namespace nave::render {
namespace {

const std::string kFurnaceConfig =
    std::string(NAVE_TEST_FIXTURES) + "/../../configs/test_furnace.toml";

std::map<std::string, std::string> ExrStatistics(const std::filesystem::path& exr) {
    std::map<std::string, std::string> values;
    auto in = OIIO::ImageInput::open(exr.string());
    if (!in) return values;
    std::istringstream text(in->spec().get_string_attribute("nave:statistics"));
    std::string word;
    while (text >> word) {
        const size_t eq = word.find('=');
        if (eq != std::string::npos) values[word.substr(0, eq)] = word.substr(eq + 1);
    }
    return values;
}

void ExpectSummaryMatchesMetadata(const std::string& extra, const std::string& budget_phrase) {
    const auto out =
        std::filesystem::temp_directory_path() / fmt::format("nave_summary_{}.exr", getpid());
    const test::CommandResult r =
        test::RunNave("render --procedural furnace:bricks=2 --config " + kFurnaceConfig +
                      " --resolution 8x6 --spp 2 --threads 1 -o " + out.string() + extra);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::map<std::string, std::string> stats = ExrStatistics(out);
    ASSERT_FALSE(stats.empty()) << out;
    auto count = [&](const std::string& key) { return FormatCount(std::stod(stats.at(key))); };
    auto bytes = [&](const std::string& key) { return FormatBytes(std::stoull(stats.at(key))); };
    for (const std::string& phrase : {
             fmt::format("({} rays: {} segments traced, {} shadow segments)", count("rays"),
                         count("segments"), count("shadow_segments")),
             fmt::format("rays moved between bricks {}, batches {}, loads {}, read {},",
                         count("brick_moves"), count("batches"), count("brick_loads"),
                         bytes("bytes_read")),
             fmt::format(", evictions {}, reloads {}, prefetched {}, resident when needed {} of ",
                         count("brick_evictions"), count("brick_reloads"), count("prefetch_loads"),
                         count("resident_hits")),
         }) {
        EXPECT_NE(r.output.find(phrase), std::string::npos) << phrase << "\n" << r.output;
    }
    const std::string budget = stats.at("brick_budget");
    const std::string expected_budget =
        budget == "in-core"
            ? budget_phrase
            : fmt::format(fmt::runtime(budget_phrase), FormatBytes(std::stoull(budget)));
    EXPECT_NE(r.output.find(fmt::format("bricks: {}, peak resident {}", expected_budget,
                                        bytes("peak_brick_bytes"))),
              std::string::npos)
        << expected_budget << "\n"
        << r.output;
    std::filesystem::remove(out);
    std::filesystem::remove(std::filesystem::path(out).replace_extension(".png"));
}

TEST(CliRenderSummaryTest, InCoreSummaryAgreesWithTheMetadata) {
    ExpectSummaryMatchesMetadata("", "in-core");
}

TEST(CliRenderSummaryTest, PagedSummaryAgreesWithTheMetadata) {
    ExpectSummaryMatchesMetadata(" --memory 1G", "budget {} (--memory 1G)");
}

}  // namespace
}  // namespace nave::render
