// `nave inspect FILE [--json] [--bricks]`: what a brick store holds, read from its header and
// tables only (no brick is decoded): bricks, triangles, bytes, bounds, grid and error bound,
// levels of detail, the medium's pieces, materials, provenance.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "src/cli/commands.h"
#include "src/core/json_string.h"
#include "src/core/memory.h"
#include "src/core/progress.h"
#include "store/store_reader.h"

namespace nave::cli {
namespace {

std::string JsonVec(const Vec3f& v) { return fmt::format("[{}, {}, {}]", v.x, v.y, v.z); }
std::string JsonVec(const Vec3d& v) { return fmt::format("[{}, {}, {}]", v.x, v.y, v.z); }
std::string Vec(const Vec3f& v) { return fmt::format("({:.4f}, {:.4f}, {:.4f})", v.x, v.y, v.z); }

/// A length in metres with a readable unit.
std::string Length(double metres) {
    if (metres >= 1) return fmt::format("{:.3g} m", metres);
    if (metres >= 1e-5) return fmt::format("{:.3g} mm", metres * 1e3);
    return fmt::format("{:.3g} um", metres * 1e6);
}

struct Summary {
    uint64_t payload_bytes = 0;
    uint64_t decoded_bytes = 0;
    uint64_t vertices = 0;
    uint32_t largest = store::kNoBrick;  // by triangles
    uint32_t empty = 0;                  // bricks with no triangle
};

/// Levels of detail at one depth (level k of every brick that has one).
struct LevelSummary {
    uint64_t bricks = 0, triangles = 0, bytes = 0, decoded_bytes = 0;
    float max_error = 0, median_error = 0;
};

/// Per level k (index k - 1), over the bricks that have it.
std::vector<LevelSummary> SummarizeLevels(const store::Store& s, uint64_t* level_bytes) {
    std::vector<LevelSummary> out;
    std::vector<std::vector<float>> errors;
    *level_bytes = 0;
    for (const store::BrickInfo& b : s.bricks()) {
        if (b.levels.size() > out.size()) {
            out.resize(b.levels.size());
            errors.resize(b.levels.size());
        }
        for (size_t k = 0; k < b.levels.size(); ++k) {
            const store::LevelInfo& l = b.levels[k];
            ++out[k].bricks;
            out[k].triangles += l.triangle_count;
            out[k].bytes += l.mesh.length;
            out[k].decoded_bytes += l.decoded_bytes;
            out[k].max_error = std::max(out[k].max_error, l.error);
            errors[k].push_back(l.error);
            *level_bytes += l.mesh.length;
        }
    }
    for (size_t k = 0; k < out.size(); ++k) {
        auto mid = errors[k].begin() + errors[k].size() / 2;
        std::nth_element(errors[k].begin(), mid, errors[k].end());
        out[k].median_error = *mid;
    }
    return out;
}

/// The bricks with an occupancy grid (format 3.4) and the bytes of those grids on disk.
std::pair<uint64_t, uint64_t> SummarizeOccupancy(const store::Store& s) {
    uint64_t bricks = 0, bytes = 0;
    for (const store::BrickInfo& b : s.bricks()) {
        bricks += b.occupancy.length > 0 ? 1 : 0;
        bytes += b.occupancy.length;
    }
    return {bricks, bytes};
}

/// The medium's pieces over all bricks (format 3.3).
struct MediumSummary {
    uint64_t voxels = 0, bytes = 0, decoded_bytes = 0, bricks = 0, bricks_without_triangles = 0;
    float max_density = 0;
};

MediumSummary SummarizeMedium(const store::Store& s) {
    MediumSummary m;
    for (const store::BrickInfo& b : s.bricks()) {
        if (b.medium.grid.length == 0) continue;
        m.voxels += b.medium.active_voxels;
        m.bytes += b.medium.grid.length;
        m.decoded_bytes += b.medium.decoded_bytes;
        ++m.bricks;
        m.bricks_without_triangles += b.triangle_count == 0 ? 1 : 0;
        m.max_density = std::max(m.max_density, b.medium.max_density);
    }
    return m;
}

/// Percent the levels add to the store's bytes without them.
double LevelGrowthPercent(const store::Store& s, uint64_t level_bytes) {
    const uint64_t without = s.file_size() - std::min(level_bytes, s.file_size());
    return without ? 100.0 * double(level_bytes) / double(without) : 0.0;
}

Summary Summarize(const store::Store& s) {
    Summary sum;
    for (const store::BrickInfo& b : s.bricks()) {
        sum.payload_bytes += b.BytesOnDisk();
        sum.decoded_bytes += b.decoded_bytes;
        sum.vertices += b.vertex_count;
        sum.empty += b.triangle_count == 0 ? 1 : 0;
        if (sum.largest == store::kNoBrick ||
            b.triangle_count > s.bricks()[sum.largest].triangle_count) {
            sum.largest = b.id;
        }
    }
    return sum;
}

// The `content=` of a store's options (what the source files said of themselves: preprocess's
// TriangleSource::content()), a line per file: "IFC4, length unit 0.001m; triangles by entity
// type: IfcWall 56, IfcWindow 60".
std::string ContentLines(const std::string& options) {
    const size_t at = options.find(" content=");
    if (at == std::string::npos) return {};
    const size_t begin = at + 9;
    const std::string content = options.substr(begin, options.find(' ', begin) - begin);
    std::string out;
    size_t file_begin = 0;
    while (file_begin <= content.size()) {
        size_t file_end = content.find('|', file_begin);
        if (file_end == std::string::npos) file_end = content.size();
        const std::string file = content.substr(file_begin, file_end - file_begin);
        std::vector<std::string> parts;
        for (size_t b = 0; b <= file.size();) {
            size_t e = file.find(';', b);
            if (e == std::string::npos) e = file.size();
            parts.push_back(file.substr(b, e - b));
            b = e + 1;
        }
        std::string line = parts[0];
        if (parts.size() > 1 && parts[1].rfind("unit=", 0) == 0) {
            line += ", length unit " + parts[1].substr(5);
        }
        if (parts.size() > 2) {
            std::string kinds = parts[2];
            for (char& c : kinds) {
                if (c == '=') c = ' ';
            }
            size_t comma = 0;
            while ((comma = kinds.find(',', comma)) != std::string::npos) {
                kinds.replace(comma, 1, ", ");
                comma += 2;
            }
            line += "; triangles by entity type: " + kinds;
        }
        out += fmt::format("  content      {}\n", line);
        file_begin = file_end + 1;
    }
    return out;
}

void PrintJson(const store::Store& s, bool list_bricks) {
    const store::StoreHeader& h = s.header();
    const Summary sum = Summarize(s);
    const double per_triangle =
        h.triangle_count ? double(s.file_size()) / double(h.triangle_count) : 0.0;
    std::string out = "{\n";
    out += fmt::format("  \"file\": {},\n", JsonString(s.path().string()));
    out += fmt::format("  \"format_version\": \"{}.{}\",\n", h.major, h.minor);
    out += fmt::format("  \"bricks\": {},\n", s.bricks().size());
    out += fmt::format("  \"empty_bricks\": {},\n", sum.empty);
    out += fmt::format("  \"triangles\": {},\n", h.triangle_count);
    out += fmt::format("  \"source_triangles\": {},\n", h.source_triangle_count);
    out += fmt::format("  \"vertices\": {},\n", sum.vertices);
    out += fmt::format("  \"bytes_on_disk\": {},\n", s.file_size());
    out += fmt::format("  \"payload_bytes\": {},\n", sum.payload_bytes);
    out += fmt::format("  \"decoded_bytes\": {},\n", sum.decoded_bytes);
    out += fmt::format("  \"bytes_per_triangle\": {:.4f},\n", per_triangle);
    out += fmt::format("  \"bounds\": {{\"min\": {}, \"max\": {}}},\n", JsonVec(h.bounds.min),
                       JsonVec(h.bounds.max));
    out += fmt::format(
        "  \"grid\": {{\"origin\": {}, \"step\": {}, \"max_axis_error\": {}, \"max_error\": "
        "{}}},\n",
        JsonVec(h.grid.origin), h.grid.step, h.grid.MaxAxisError(),
        h.grid.MaxAxisError() * std::sqrt(3.0));
    if (sum.largest != store::kNoBrick) {
        const store::BrickInfo& b = s.bricks()[sum.largest];
        out += fmt::format(
            "  \"largest_brick\": {{\"id\": {}, \"triangles\": {}, \"vertices\": {}, \"bytes\": "
            "{}, "
            "\"decoded_bytes\": {}}},\n",
            b.id, b.triangle_count, b.vertex_count, b.BytesOnDisk(), b.decoded_bytes);
    }
    uint64_t level_bytes = 0;
    const std::vector<LevelSummary> levels = SummarizeLevels(s, &level_bytes);
    out += "  \"levels\": [";
    for (size_t k = 0; k < levels.size(); ++k) {
        const LevelSummary& l = levels[k];
        out += fmt::format(
            "{}\n    {{\"level\": {}, \"bricks\": {}, \"triangles\": {}, \"bytes\": {}, "
            "\"decoded_bytes\": {}, \"max_error\": {}, \"median_error\": {}}}",
            k ? "," : "", k + 1, l.bricks, l.triangles, l.bytes, l.decoded_bytes, l.max_error,
            l.median_error);
    }
    out += levels.empty() ? "],\n" : "\n  ],\n";
    out += fmt::format("  \"level_bytes\": {},\n", level_bytes);
    out += fmt::format("  \"level_growth_percent\": {:.4f},\n", LevelGrowthPercent(s, level_bytes));
    if (h.medium_grid.empty()) {
        out += "  \"medium\": null,\n";
    } else {
        const MediumSummary m = SummarizeMedium(s);
        out += fmt::format(
            "  \"medium\": {{\"grid\": {}, \"voxels\": {}, \"bytes\": {}, \"decoded_bytes\": {}, "
            "\"bricks\": {}, \"bricks_without_triangles\": {}, \"max_density\": {}}},\n",
            JsonString(h.medium_grid), m.voxels, m.bytes, m.decoded_bytes, m.bricks,
            m.bricks_without_triangles, m.max_density);
    }
    const auto [occupancy_bricks, occupancy_bytes] = SummarizeOccupancy(s);
    out += fmt::format("  \"occupancy\": {{\"bricks\": {}, \"bytes\": {}}},\n", occupancy_bricks,
                       occupancy_bytes);
    out += "  \"materials\": [";
    for (size_t i = 0; i < s.materials().size(); ++i) {
        const store::MaterialRecord& m = s.materials()[i];
        out += fmt::format(
            "{}\n    {{\"id\": {}, \"name\": {}, \"diffuse\": [{}, {}, {}], \"textures\": {{",
            i ? "," : "", i, JsonString(m.name), m.diffuse[0], m.diffuse[1], m.diffuse[2]);
        bool first = true;
        for (const auto& [slot, path] : m.textures) {
            out += fmt::format("{}{}: {}", first ? "" : ", ", JsonString(slot), JsonString(path));
            first = false;
        }
        out += "}}";
    }
    out += s.materials().empty() ? "],\n" : "\n  ],\n";
    out += "  \"provenance\": {\"source_files\": [";
    for (size_t i = 0; i < h.provenance.source_files.size(); ++i) {
        out += (i ? ", " : "") + JsonString(h.provenance.source_files[i]);
    }
    out += fmt::format("], \"tool_version\": {}, \"options\": {}}}",
                       JsonString(h.provenance.tool_version), JsonString(h.provenance.options));
    if (list_bricks) {
        out += ",\n  \"brick_list\": [";
        for (const store::BrickInfo& b : s.bricks()) {
            const store::BrickMediumInfo& m = b.medium;
            const std::string medium =
                m.grid.length == 0
                    ? std::string("null")
                    : fmt::format(
                          "{{\"voxels\": {}, \"bytes\": {}, \"offset\": {}, \"decoded_bytes\": "
                          "{}, \"max_density\": {}}}",
                          m.active_voxels, m.grid.length, m.grid.offset, m.decoded_bytes,
                          m.max_density);
            out += fmt::format(
                "{}\n    {{\"id\": {}, \"triangles\": {}, \"vertices\": {}, \"bytes\": {}, "
                "\"offset\": {}, \"cell\": {{\"min\": {}, \"max\": {}}}, \"medium\": {}}}",
                b.id ? "," : "", b.id, b.triangle_count, b.vertex_count, b.BytesOnDisk(),
                b.mesh.offset, JsonVec(b.cell.min), JsonVec(b.cell.max), medium);
        }
        out += s.bricks().empty() ? "]" : "\n  ]";
    }
    out += "\n}\n";
    std::fputs(out.c_str(), stdout);
}

void PrintText(const store::Store& s, bool list_bricks) {
    const store::StoreHeader& h = s.header();
    const Summary sum = Summarize(s);
    std::string out;
    out += fmt::format("{}: nave brick store, format {}.{}\n", s.path().string(), h.major, h.minor);
    out += fmt::format("  bricks       {}{}\n", s.bricks().size(),
                       sum.empty ? fmt::format(" ({} without triangles)", sum.empty) : "");
    const double duplicated =
        h.source_triangle_count
            ? 100.0 * (double(h.triangle_count) - double(h.source_triangle_count)) /
                  double(h.source_triangle_count)
            : 0.0;
    out += fmt::format(
        "  triangles    {} stored ({}), {} in the source ({:+.2f} % from cutting into bricks "
        "and dropping triangles that collapse on the grid)\n",
        FormatCount(double(h.triangle_count)), h.triangle_count,
        FormatCount(double(h.source_triangle_count)), duplicated);
    out += fmt::format("  vertices     {}\n", FormatCount(double(sum.vertices)));
    out += fmt::format("  on disk      {} ({} bytes), {:.2f} bytes/triangle; brick payloads {}\n",
                       FormatBytes(s.file_size()), s.file_size(),
                       h.triangle_count ? double(s.file_size()) / double(h.triangle_count) : 0.0,
                       FormatBytes(sum.payload_bytes));
    out += fmt::format("  decoded      {} if every brick were resident\n",
                       FormatBytes(sum.decoded_bytes));
    out += fmt::format("  bounds       {} - {} (size {})\n", Vec(h.bounds.min), Vec(h.bounds.max),
                       Vec(h.bounds.Empty() ? Vec3f{} : h.bounds.Diagonal()));
    out += fmt::format(
        "  grid         step {}, origin ({}, {}, {}); max position error {} per axis, {} in "
        "length\n",
        Length(h.grid.step), h.grid.origin.x, h.grid.origin.y, h.grid.origin.z,
        Length(h.grid.MaxAxisError()), Length(h.grid.MaxAxisError() * std::sqrt(3.0)));
    if (sum.largest != store::kNoBrick) {
        const store::BrickInfo& b = s.bricks()[sum.largest];
        out += fmt::format(
            "  largest      brick {}: {} triangles, {} vertices, {} on disk, {} decoded\n", b.id,
            FormatCount(double(b.triangle_count)), FormatCount(double(b.vertex_count)),
            FormatBytes(b.BytesOnDisk()), FormatBytes(b.decoded_bytes));
    }
    uint64_t level_bytes = 0;
    const std::vector<LevelSummary> levels = SummarizeLevels(s, &level_bytes);
    if (levels.empty()) {
        out += "  levels       none\n";
    } else {
        out += fmt::format("  levels       {} on disk, {:+.2f} % to the store without them\n",
                           FormatBytes(level_bytes), LevelGrowthPercent(s, level_bytes));
        for (size_t k = 0; k < levels.size(); ++k) {
            const LevelSummary& l = levels[k];
            out += fmt::format(
                "    level {}: {} bricks, {} triangles ({:.2f} % of the bricks'), {} on disk, {} "
                "decoded; error max {}, median {}\n",
                k + 1, l.bricks, FormatCount(double(l.triangles)),
                h.triangle_count ? 100.0 * double(l.triangles) / double(h.triangle_count) : 0.0,
                FormatBytes(l.bytes), FormatBytes(l.decoded_bytes), Length(l.max_error),
                Length(l.median_error));
        }
    }
    if (h.medium_grid.empty()) {
        out += "  medium       none\n";
    } else {
        const MediumSummary m = SummarizeMedium(s);
        out += fmt::format(
            "  medium       grid '{}': {} voxels in {} bricks ({} without triangles), {} on disk, "
            "{} decoded; largest density {:.6g}\n",
            h.medium_grid, FormatCount(double(m.voxels)), m.bricks, m.bricks_without_triangles,
            FormatBytes(m.bytes), FormatBytes(m.decoded_bytes), m.max_density);
    }
    const auto [occupancy_bricks, occupancy_bytes] = SummarizeOccupancy(s);
    out += occupancy_bricks == 0
               ? std::string("  occupancy    none (rays load every brick they cross)\n")
               : fmt::format("  occupancy    {} bricks' grids, {} on disk\n", occupancy_bricks,
                             FormatBytes(occupancy_bytes));
    out += fmt::format("  materials    {}\n", s.materials().size());
    for (size_t i = 0; i < s.materials().size(); ++i) {
        const store::MaterialRecord& m = s.materials()[i];
        std::string textures;
        for (const auto& [slot, path] : m.textures) textures += fmt::format(" {}={}", slot, path);
        out += fmt::format("    {:>4}  {:<24} diffuse ({:.3f}, {:.3f}, {:.3f}){}\n", i, m.name,
                           m.diffuse[0], m.diffuse[1], m.diffuse[2], textures);
    }
    std::string sources;
    for (const std::string& f : h.provenance.source_files)
        sources += (sources.empty() ? "" : ", ") + f;
    out += fmt::format("  sources      {}\n", sources.empty() ? "(none recorded)" : sources);
    out += fmt::format("  made by      {}\n",
                       h.provenance.tool_version.empty() ? "(unknown)" : h.provenance.tool_version);
    out += ContentLines(h.provenance.options);
    out += fmt::format("  options      {}\n",
                       h.provenance.options.empty() ? "(none)" : h.provenance.options);
    if (list_bricks) {
        out += "  id        triangles    vertices       bytes       offset  cell\n";
        for (const store::BrickInfo& b : s.bricks()) {
            out += fmt::format("  {:<8} {:>10} {:>11} {:>11}  0x{:<10x} {} - {}\n", b.id,
                               b.triangle_count, b.vertex_count, b.BytesOnDisk(), b.mesh.offset,
                               Vec(b.cell.min), Vec(b.cell.max));
            for (size_t k = 0; k < b.levels.size(); ++k) {
                const store::LevelInfo& l = b.levels[k];
                out += fmt::format("    level {} {:>10} {:>11} {:>11}  0x{:<10x} error {}\n", k + 1,
                                   l.triangle_count, l.vertex_count, l.mesh.length, l.mesh.offset,
                                   Length(l.error));
            }
            const store::BrickMediumInfo& m = b.medium;
            if (m.grid.length > 0) {
                out += fmt::format(
                    "    medium  {:>10} voxels {:>11}  0x{:<10x} majorant {:.6g}, {} decoded\n",
                    m.active_voxels, m.grid.length, m.grid.offset, m.max_density,
                    FormatBytes(m.decoded_bytes));
            }
        }
    }
    std::fputs(out.c_str(), stdout);
}

}  // namespace

void RegisterInspectCommand(CLI::App& app, CommandRun& run) {
    CLI::App* cmd = app.add_subcommand("inspect",
                                       "Describe a brick store: bricks, triangles, bytes, bounds, "
                                       "grid and error, materials, provenance");
    auto file = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    auto bricks = std::make_shared<bool>(false);
    cmd->add_option("FILE", *file, "The .nave store")->required();
    cmd->add_flag("--json", *json, "Print JSON on stdout instead of text");
    cmd->add_flag("--bricks", *bricks,
                  "Also list every brick (id, triangles, vertices, bytes, offset, cell; its "
                  "levels and its piece of the medium)");
    cmd->callback([&run, file, json, bricks] {
        run = [file, json, bricks]() -> Status {
            NAVE_ASSIGN_OR_RETURN(std::unique_ptr<store::Store> s, store::Store::Open(*file));
            if (*json) {
                PrintJson(*s, *bricks);
            } else {
                PrintText(*s, *bricks);
            }
            return Status::Ok();
        };
    });
}

}  // namespace nave::cli
