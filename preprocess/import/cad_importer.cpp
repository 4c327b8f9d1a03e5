#include "preprocess/import/cad_importer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "preprocess/import/cad_plugin.h"
#include "preprocess/import/file_extension.h"
#include "preprocess/import/ifc_plugin.h"
#include "preprocess/import/indexed_mesh_source.h"
#include "preprocess/import/model_wire.h"
#include "src/core/child_process.h"
#include "src/core/log.h"

namespace nave::preprocess {
namespace {

// How long Open CASCADE may take on a file: its STEP reader and the tessellation of a large
// assembly take minutes on a valid file of tens of MiB; only a reader stuck on damaged data
// reaches this.
constexpr double kCadBaseSeconds = 300;
constexpr double kCadSecondsPerMiB = 60;

// An unlinked temporary file: it has no name, so it is gone once closed, however nave ends.
class Spool {
  public:
    static StatusOr<Spool> Create() {
        const char* tmp = std::getenv("TMPDIR");
        const std::string dir = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
        std::string name = dir + "/nave-cad-XXXXXX";
        const int fd = mkstemp(name.data());
        if (fd < 0) {
            return IoError("cannot create a temporary file in {} for the tessellated parts: {}",
                           dir, std::strerror(errno));
        }
        unlink(name.c_str());
        return Spool(fd, dir);
    }
    Spool(Spool&& o) noexcept : fd_(o.fd_), dir_(std::move(o.dir_)) { o.fd_ = -1; }
    Spool(const Spool&) = delete;
    Spool& operator=(const Spool&) = delete;
    Spool& operator=(Spool&&) = delete;
    ~Spool() {
        if (fd_ >= 0) close(fd_);
    }
    int fd() const { return fd_; }
    const std::string& dir() const { return dir_; }

  private:
    Spool(int fd, std::string dir) : fd_(fd), dir_(std::move(dir)) {}
    int fd_ = -1;
    std::string dir_;
};

// IFC's triangles per entity type as text: "IfcWall=12,IfcWindow=4" (with "=" and ","), for the
// summary line, the store's content and the log.
std::string KindsText(const CadReadSummary& s, const char* pair, const char* between) {
    std::string kinds;
    for (const auto& [kind, triangles] : s.by_kind) {
        kinds += fmt::format("{}{}{}{}", kinds.empty() ? "" : between, kind, pair, triangles);
    }
    return kinds;
}

// The summary travels as one line of tab-separated fields before the material table.
std::string EncodeSummary(const CadReadSummary& s) {
    const std::string kinds = KindsText(s, "=", ",");
    return fmt::format("{}\t{}\t{:.17g}\t{:.17g}\t{}\t{}\t{}\t{}\t{}\t{}\n", s.format, s.file_unit,
                       s.linear_deflection, s.angular_deflection, s.parts, s.instances, s.triangles,
                       s.faces_without_mesh, s.skipped_products, kinds);
}

std::vector<std::string> Split(std::string_view text, char separator) {
    std::vector<std::string> fields;
    size_t begin = 0;
    while (true) {
        const size_t end = text.find(separator, begin);
        fields.emplace_back(text.substr(begin, end == std::string_view::npos ? end : end - begin));
        if (end == std::string_view::npos) return fields;
        begin = end + 1;
    }
}

StatusOr<CadReadSummary> DecodeSummary(std::string_view line, const std::string& what) {
    const std::vector<std::string> fields = Split(line, '\t');
    if (fields.size() != 10) return DataLossError("{}: the CAD reader's summary is damaged", what);
    CadReadSummary s;
    s.format = fields[0];
    s.file_unit = fields[1];
    s.linear_deflection = std::strtod(fields[2].c_str(), nullptr);
    s.angular_deflection = std::strtod(fields[3].c_str(), nullptr);
    s.parts = std::strtoull(fields[4].c_str(), nullptr, 10);
    s.instances = std::strtoull(fields[5].c_str(), nullptr, 10);
    s.triangles = std::strtoull(fields[6].c_str(), nullptr, 10);
    s.faces_without_mesh = std::strtoull(fields[7].c_str(), nullptr, 10);
    s.skipped_products = std::strtoull(fields[8].c_str(), nullptr, 10);
    if (!fields[9].empty()) {
        for (const std::string& kind : Split(fields[9], ',')) {
            const size_t eq = kind.find('=');
            if (eq == std::string::npos) continue;
            s.by_kind.emplace_back(kind.substr(0, eq),
                                   std::strtoull(kind.c_str() + eq + 1, nullptr, 10));
        }
    }
    return s;
}

/// Reads a file with one of the plugins: emits meshes, fills materials.
using PluginRead =
    std::function<StatusOr<CadReadSummary>(const std::function<Status(IndexedMesh&&)>& emit,
                                           std::vector<store::MaterialRecord>& materials)>;

// The child: reads the file with the plugin, appending every part's meshes to the spool as
// [byte count, EncodeImportedModel of one mesh], then sends the summary and the materials, or
// reports the plugin's error (ReportStatusFromChild: any other end is a crash).
int ReadInChild(const PluginRead& read, const std::filesystem::path& path, const Spool& spool,
                int out_fd) {
    std::vector<store::MaterialRecord> materials;
    auto emit = [&](IndexedMesh&& mesh) -> Status {
        ImportedModel one;
        one.meshes.push_back(std::move(mesh));
        const std::string bytes = EncodeImportedModel(one);
        const uint64_t size = bytes.size();
        if (!WriteAllToFd(spool.fd(), &size, sizeof(size)) ||
            !WriteAllToFd(spool.fd(), bytes.data(), bytes.size())) {
            return IoError("{}: cannot write its tessellated parts to a temporary file in {}: {}",
                           path.string(), spool.dir(), std::strerror(errno));
        }
        return Status::Ok();
    };
    StatusOr<CadReadSummary> summary = read(emit, materials);
    if (!summary.ok()) return ReportStatusFromChild(out_fd, summary.status());
    ImportedModel table;
    table.materials = std::move(materials);
    const std::string bytes = EncodeSummary(*summary) + EncodeImportedModel(table);
    return WriteAllToFd(out_fd, bytes.data(), bytes.size())
               ? 0
               : ReportStatusFromChild(
                     out_fd, IoError("{}: cannot send the parts' materials", path.string()));
}

// Reads the spool back in order, one mesh at a time.
class SpoolReader {
  public:
    SpoolReader(Spool spool, std::string what) : spool_(std::move(spool)), what_(std::move(what)) {}

    Status Rewind() {
        struct stat st {};
        if (fstat(spool_.fd(), &st) != 0 || lseek(spool_.fd(), 0, SEEK_SET) != 0) {
            return IoError("{}: cannot read back its tessellated parts: {}", what_,
                           std::strerror(errno));
        }
        size_ = uint64_t(st.st_size);
        return Status::Ok();
    }

    StatusOr<bool> Next(IndexedMesh* mesh) {
        if (pos_ == size_) return false;
        uint64_t bytes = 0;
        NAVE_RETURN_IF_ERROR(Read(&bytes, sizeof(bytes)));
        if (bytes > size_ - pos_) {
            return DataLossError("{}: its tessellated parts end short at byte {} of {}", what_,
                                 pos_, size_);
        }
        std::string record(size_t(bytes), '\0');
        NAVE_RETURN_IF_ERROR(Read(record.data(), record.size()));
        NAVE_ASSIGN_OR_RETURN(ImportedModel one, DecodeImportedModel(record, what_));
        if (one.meshes.size() != 1) {
            return DataLossError("{}: a tessellated part holds {} meshes, not one", what_,
                                 one.meshes.size());
        }
        *mesh = std::move(one.meshes[0]);
        return true;
    }

  private:
    Status Read(void* data, size_t size) {
        auto* out = static_cast<char*>(data);
        size_t got = 0;
        while (got < size) {
            const ssize_t n = read(spool_.fd(), out + got, size - got);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                return DataLossError("{}: its tessellated parts end short at byte {}", what_,
                                     pos_ + got);
            }
            got += size_t(n);
        }
        pos_ += size;
        return Status::Ok();
    }

    Spool spool_;
    std::string what_;
    uint64_t size_ = 0, pos_ = 0;
};

}  // namespace

bool IsCadFile(const std::filesystem::path& path) {
    const std::string ext = LowerExtension(path);
    return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs" ||
           (ext == ".ifc" && IfcPluginBuilt());
}

namespace {

// TriangleSource::content(): "IFC4;unit=0.001m;IfcWall=56,IfcWindow=60", "STEP;unit=millimetre".
std::string Content(const CadReadSummary& s) {
    std::string unit;
    for (char c : s.file_unit) {
        if (c != ' ' && c != ';' && c != '|') unit += c;
    }
    std::string content = s.format + ";unit=" + (unit.empty() ? "unnamed" : unit);
    const std::string kinds = KindsText(s, "=", ",");
    return kinds.empty() ? content : content + ";" + kinds;
}

// A file cut short may still parse (at the end of an entity) and give part of a model without a
// word: every STEP physical file (STEP and IFC, ISO 10303-21) ends with END-ISO-10303-21; and
// every IGES file with its terminate section, a line marked T in column 73.
Status CheckNotCutShort(const std::filesystem::path& path, const std::string& ext) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return IoError("{}: cannot open it", path.string());
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    const std::streamoff tail = std::min<std::streamoff>(size, 256);
    in.seekg(size - tail);
    std::string end(size_t(tail), '\0');
    in.read(end.data(), tail);
    while (!end.empty() && std::isspace(static_cast<unsigned char>(end.back())) != 0) {
        end.pop_back();
    }
    if (ext == ".iges" || ext == ".igs") {
        const size_t line = end.find_last_of('\n');
        const std::string last = line == std::string::npos ? end : end.substr(line + 1);
        if (last.size() >= 73 && last[72] == 'T') return Status::Ok();
        return DataLossError(
            "{}: cut short: an IGES file ends with its terminate section (a line marked T in "
            "column 73), and this one's last line is not one",
            path.string());
    }
    const std::string marker = "END-ISO-10303-21;";
    if (end.size() >= marker.size() &&
        end.compare(end.size() - marker.size(), marker.size(), marker) == 0) {
        return Status::Ok();
    }
    return DataLossError(
        "{}: cut short: a STEP physical file ({}) ends with END-ISO-10303-21; and this one does "
        "not",
        path.string(), ext == ".ifc" ? "IFC" : "STEP");
}

// What the log says of a file read.
std::string Describe(const std::filesystem::path& path, const CadReadSummary& s) {
    if (s.format.rfind("IFC", 0) == 0) {
        return fmt::format(
            "{}: {} with a length unit of {}, converted to metres; {} products with surfaces ({} "
            "spaces, openings and annotations not rendered), {} triangles: {}",
            path.filename().string(), s.format, s.file_unit, s.instances, s.skipped_products,
            s.triangles, KindsText(s, " ", ", "));
    }
    return fmt::format(
        "{}: {} in {}, converted to metres; {} parts in {} placements, {} triangles (linear "
        "deflection {:.3g} m, angular {:.0f} degrees)",
        path.filename().string(), s.format, s.file_unit.empty() ? "an unnamed unit" : s.file_unit,
        s.parts, s.instances, s.triangles, s.linear_deflection,
        s.angular_deflection * 180.0 / 3.14159265358979323846);
}

}  // namespace

StatusOr<std::unique_ptr<TriangleSource>> OpenCad(const std::filesystem::path& path,
                                                  double precision) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return NotFoundError("{}: no such file", path.string());
    const std::string ext = LowerExtension(path);
    // Plugins are loaded here, before the fork: the child then only calls into them (dlopen after
    // a fork of a process with threads could wait forever on a lock another thread held).
    PluginRead read;
    std::string library;
    if (ext == ".ifc") {
        NAVE_ASSIGN_OR_RETURN(const IfcPlugin* plugin, LoadIfcPlugin());
        library = "IFC++";
        read = [plugin, &path](const auto& emit, auto& materials) {
            return plugin->ReadIfc(path, emit, materials);
        };
    } else {
        NAVE_ASSIGN_OR_RETURN(const CadPlugin* plugin, LoadCadPlugin());
        library = "Open CASCADE";
        read = [plugin, &path, precision](const auto& emit, auto& materials) {
            return plugin->ReadBrep(path, {precision}, emit, materials);
        };
    }
    NAVE_RETURN_IF_ERROR(CheckNotCutShort(path, ext));
    NAVE_ASSIGN_OR_RETURN(Spool spool, Spool::Create());
    const uintmax_t file_bytes = std::filesystem::file_size(path, ec);
    const double time_limit =
        kCadBaseSeconds + kCadSecondsPerMiB * double(ec ? 0 : file_bytes) / double(1 << 20);
    log::Info("{}: reading and tessellating with {}", path.string(), library);
    NAVE_ASSIGN_OR_RETURN(
        ChildOutcome child,
        RunInChildProcess([&](int fd) { return ReadInChild(read, path, spool, fd); }, time_limit));
    if (child.timed_out) {
        return DataLossError(
            "{}: {} was stopped after {:.0f} s reading this file of {} bytes (its limit: {:.0f} s "
            "+ {:.0f} s per MiB), the sign of a reader stuck on damaged data; repair or re-export "
            "it",
            path.string(), library, time_limit, ec ? 0 : file_bytes, kCadBaseSeconds,
            kCadSecondsPerMiB);
    }
    if (!child.exited || child.exit_code != 0) {
        Status reported;
        if (ChildReportedStatus(child, &reported)) return reported;
        return DataLossError(
            "{}: {} {} reading this file; the file is damaged or uses something it cannot read: "
            "repair or re-export it",
            path.string(), library, DescribeChildEnd(child));
    }
    const std::string what = path.string();
    const size_t line_end = child.output.find('\n');
    if (line_end == std::string::npos) {
        return DataLossError("{}: the CAD reader sent no summary", what);
    }
    NAVE_ASSIGN_OR_RETURN(CadReadSummary summary,
                          DecodeSummary(std::string_view(child.output).substr(0, line_end), what));
    NAVE_ASSIGN_OR_RETURN(
        ImportedModel table,
        DecodeImportedModel(std::string_view(child.output).substr(line_end + 1), what));
    log::Info("{}", Describe(path, summary));
    ImportWarnings warnings;
    for (uint64_t i = 0; i < summary.faces_without_mesh; ++i) {
        warnings.Add("faces Open CASCADE could not tessellate, skipped", path.filename().string());
    }
    auto reader = std::make_shared<SpoolReader>(std::move(spool), what);
    NAVE_RETURN_IF_ERROR(reader->Rewind());
    auto source = std::make_unique<IndexedMeshSource>(path.filename().string(), "m",
                                                      std::vector<IndexedMesh>{},
                                                      std::move(table.materials), warnings);
    source->SetContent(Content(summary));
    source->SetMeshFeed([reader](IndexedMesh* next) { return reader->Next(next); },
                        summary.triangles);
    return std::unique_ptr<TriangleSource>(std::move(source));
}

}  // namespace nave::preprocess
