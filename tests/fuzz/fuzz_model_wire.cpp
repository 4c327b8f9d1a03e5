// The byte stream a child importer process sends back (model_wire.h): decoding arbitrary bytes
// returns a Status or a model whose meshes IndexedMeshSource can serve without reading out of
// bounds.

#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/model_wire.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace nave::preprocess;
    nave::StatusOr<ImportedModel> model =
        DecodeImportedModel(nave::fuzz::AsView(data, size), "fuzz.fbx");
    if (!model.ok()) return 0;
    // What decodes must survive its own round trip.
    if (!DecodeImportedModel(EncodeImportedModel(*model), "fuzz.fbx").ok()) std::abort();
    nave::fuzz::Drain(std::unique_ptr<TriangleSource>(
        new IndexedMeshSource("fuzz.fbx", "unknown", std::move(model->meshes),
                              std::move(model->materials), ImportWarnings())));
    return 0;
}
