// The STEP, IGES and IFC path as `nave preprocess` takes it (preprocess/import/cad_importer.h):
// Open CASCADE or IFC++ in a child process (one fork per input) writing the tessellated parts to a
// temporary file, nave reading them back. The first byte picks the extension as in fuzz_cad.
// Whatever the library does to the child (it dereferences null on some damaged STEP entities, which
// fuzz_cad finds within a minute), nave must return a Status. The child's coverage does not reach
// libFuzzer, so this target is run on the corpus and the inputs fuzz_cad finds.

#include "drain.h"
#include "fuzz_file.h"
#include "isolated_child.h"
#include "preprocess/import/cad_importer.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    pthread_atfork(nullptr, nullptr, nave::fuzz::LimitForkedChild);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    static const char* const kNames[] = {"input.step", "input.igs", "input.ifc"};
    const auto path = nave::fuzz::WriteInput(
        kNames[data[0] % 3], std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1));
    nave::fuzz::Drain(nave::preprocess::OpenCad(path, 0));
    return 0;
}
