// A STEP or IGES file as `nave preprocess` reads one, in this process: the first byte picks the
// extension (even: .step, odd: .igs), the rest is the file, read and tessellated by the CAD plugin
// (Open CASCADE) and every mesh it hands over checked as nave's importers check theirs. `nave`
// itself runs the plugin in a child process (cad_importer.h), so a crash inside Open CASCADE ends
// the child, not nave: this target looks for what happens before that, in nave's own code around
// the library, and for what the library does with damaged files. Not in scripts/fuzz.sh's default
// run: docs/fuzzing.md says why and how to run it.

#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz_file.h"
#include "preprocess/import/cad_plugin.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const nave::preprocess::CadPlugin* plugin = [] {
        auto loaded = nave::preprocess::LoadCadPlugin();
        if (!loaded.ok()) std::abort();  // a build without the plugin fuzzes nothing
        return *loaded;
    }();
    if (size == 0) return 0;
    const char* name = data[0] % 2 == 0 ? "input.step" : "input.igs";
    const auto file = nave::fuzz::WriteInput(
        name, std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1));
    std::vector<nave::store::MaterialRecord> materials;
    auto checked = [&](nave::preprocess::IndexedMesh&& mesh) -> nave::Status {
        // Every index names a position, every material a record, as the source reading them
        // back assumes only after checking.
        for (uint32_t i : mesh.indices) {
            if (i >= mesh.positions.size()) std::abort();
        }
        if (mesh.material >= materials.size()) std::abort();
        if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) std::abort();
        return nave::Status::Ok();
    };
    (void)plugin->ReadBrep(file, {}, checked, materials);
    return 0;
}
