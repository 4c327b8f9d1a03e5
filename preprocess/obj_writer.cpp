#include "preprocess/obj_writer.h"

#include <fmt/format.h>

#include "src/core/file.h"
#include "src/core/progress.h"

namespace nave::preprocess {

StatusOr<ObjWriteStats> WriteObj(TriangleSource& source, const std::filesystem::path& obj_path) {
    std::filesystem::path mtl_path = obj_path;
    mtl_path.replace_extension(".mtl");
    NAVE_ASSIGN_OR_RETURN(AtomicFile obj, AtomicFile::Create(obj_path));
    NAVE_ASSIGN_OR_RETURN(AtomicFile mtl, AtomicFile::Create(mtl_path));
    NAVE_RETURN_IF_ERROR(obj.Write(fmt::format("# {} written by nave\nmtllib {}\n", source.name(),
                                               mtl_path.filename().string())));
    ObjWriteStats stats;
    ProgressBar progress("generate", source.progress_total(), "parts");
    std::vector<Triangle> batch;
    fmt::memory_buffer out;
    uint64_t vertices = 0, normals = 0;
    int64_t material = -1;
    while (true) {
        NAVE_ASSIGN_OR_RETURN(bool more, source.Next(batch, 1 << 14));
        if (!more) break;
        out.clear();
        for (const Triangle& t : batch) {
            if (int64_t(t.material) != material) {
                material = t.material;
                fmt::format_to(std::back_inserter(out), "usemtl {}\n",
                               source.materials().at(t.material).name);
            }
            for (int j = 0; j < 3; ++j)
                fmt::format_to(std::back_inserter(out), "v {} {} {}\n", t.p[j].x, t.p[j].y,
                               t.p[j].z);
            if (t.has_normals) {
                for (int j = 0; j < 3; ++j) {
                    fmt::format_to(std::back_inserter(out), "vn {:.4f} {:.4f} {:.4f}\n", t.n[j].x,
                                   t.n[j].y, t.n[j].z);
                }
                fmt::format_to(std::back_inserter(out), "f {}//{} {}//{} {}//{}\n", vertices + 1,
                               normals + 1, vertices + 2, normals + 2, vertices + 3, normals + 3);
                normals += 3;
            } else {
                fmt::format_to(std::back_inserter(out), "f {} {} {}\n", vertices + 1, vertices + 2,
                               vertices + 3);
            }
            vertices += 3;
        }
        stats.triangles += batch.size();
        NAVE_RETURN_IF_ERROR(obj.Write(out.data(), out.size()));
        progress.Add(source.progress_done() - progress.done());
    }
    progress.Finish();
    out.clear();
    for (const auto& m : source.materials()) {
        fmt::format_to(std::back_inserter(out),
                       "newmtl {}\nKd {} {} {}\nKs {} {} {}\nKe {} {} {}\nNi {}\nd {}\n", m.name,
                       m.diffuse[0], m.diffuse[1], m.diffuse[2], m.specular[0], m.specular[1],
                       m.specular[2], m.emission[0], m.emission[1], m.emission[2], m.ior,
                       m.opacity);
        for (const auto& [slot, file] : m.textures)
            fmt::format_to(std::back_inserter(out), "{} {}\n", slot, file);
        fmt::format_to(std::back_inserter(out), "\n");
    }
    NAVE_RETURN_IF_ERROR(mtl.Write(out.data(), out.size()));
    stats.bytes = obj.size() + mtl.size();
    NAVE_RETURN_IF_ERROR(mtl.Commit());
    NAVE_RETURN_IF_ERROR(obj.Commit());
    return stats;
}

}  // namespace nave::preprocess
