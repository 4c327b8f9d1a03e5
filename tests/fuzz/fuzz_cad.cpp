// A STEP, IGES or IFC file as `nave preprocess` reads one, in this process: the first byte picks
// the extension (modulo 3: .step, .igs, .ifc), the rest is the file, read and tessellated by the
// CAD plugin (Open CASCADE) or the IFC plugin (IFC++), and every mesh they hand over checked as
// nave's importers check theirs. `nave` itself runs the plugins in a child process
// (cad_importer.h), so a crash inside a library ends the child, not nave: this target looks for
// what the libraries do with damaged files and for nave's own code around them. Not in
// scripts/fuzz.sh's default run (Open CASCADE crashes within a minute): docs/fuzzing.md says how
// to run it; fuzz_cad_isolated, in the default run, takes the path `nave` takes.

#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz_file.h"
#include "preprocess/import/cad_plugin.h"
#include "preprocess/import/ifc_plugin.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const nave::preprocess::CadPlugin* cad = [] {
        auto loaded = nave::preprocess::LoadCadPlugin();
        return loaded.ok() ? *loaded : nullptr;
    }();
    static const nave::preprocess::IfcPlugin* ifc = [] {
        auto loaded = nave::preprocess::LoadIfcPlugin();
        return loaded.ok() ? *loaded : nullptr;
    }();
    if (cad == nullptr && ifc == nullptr) std::abort();  // a build without them fuzzes nothing
    if (size == 0) return 0;
    static const char* const kNames[] = {"input.step", "input.igs", "input.ifc"};
    const int format = data[0] % 3;
    const auto file = nave::fuzz::WriteInput(
        kNames[format], std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1));
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
    if (format == 2) {
        if (ifc != nullptr) (void)ifc->ReadIfc(file, checked, materials);
    } else if (cad != nullptr) {
        (void)cad->ReadBrep(file, {}, checked, materials);
    }
    return 0;
}
