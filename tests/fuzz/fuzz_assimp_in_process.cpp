// Assimp in this process, on the formats of assimp_formats.h (the first byte picks the extension):
// finds inputs on which Assimp itself crashes, and exercises nave's conversion of what it returns
// (the scene to ImportedModel, the byte stream, the triangle source). nave contains Assimp's
// crashes by running it in a child process, which fuzz_assimp_isolated checks; docs/fuzzing.md says
// how to run this target past them and replay them through the isolated path.
//
// Assimp's failed assertions do not end this process (below); its other crashes still do.

#include <stdexcept>
#include <string>

#include "assimp_formats.h"
#include "drain.h"
#include "fuzz_file.h"
#include "preprocess/import/assimp_scene.h"
#include "preprocess/import/model_wire.h"

// Debian's libassimp5 is built with ASSIMP_BUILD_DEBUG: every ai_assert that fails calls
// Assimp::aiAssertViolation, whose handler prints the expression and calls abort(). On mutated OFF
// files about one input in 40 fails one (most often TriangulateProcess.cpp(238)), and each abort
// would restart the fuzzer. This definition replaces the library's for this executable only:
// libassimp exports the function and calls it through its PLT (all of its 1 347 call sites
// in 5.2.5; `objdump -d` shows no direct call), so the dynamic linker binds those calls to the
// executable's definition, which comes first in the lookup order. nave's libraries and the `nave`
// executable do not define it and keep Assimp's abort, which their child process turns into an
// error.
//
// Why throwing is sound: the exception is raised at the failed assertion, so Assimp never runs a
// line past a broken invariant; unwinding runs only destructors and catch handlers. aiImportFile
// catches exceptions from the readers and the post-processing steps alike (its readers report
// every error they detect by throwing DeadlyImportError the same way), frees the importer and
// returns no scene, keeping the message: the target sees an InvalidArgument naming "ai_assert
// failure in ./code/PostProcessing/TriangulateProcess.cpp(238)" for square_abort_*.off. An
// assertion inside a noexcept function (a destructor) or below a frame without unwind tables ends
// in std::terminate, an abort that libFuzzer reports like the default handler's: never a silent
// pass.
//
// What it cannot cover: a segmentation fault, bus error, stack overflow or ASan report in Assimp
// still ends the process (hence `-fork=1 -ignore_crashes=1` in docs/fuzzing.md); a destructor
// running over a half-built scene may crash too, and that is reported as Assimp's crash like the
// others. Whatever Assimp had allocated through raw pointers when the assertion failed is
// abandoned: those leaks are Assimp's, and
// __lsan_default_suppressions below suppresses every leak whose allocation stack passes through
// libassimp. nave's code allocates nothing from inside Assimp (nave installs no IOSystem, logger
// or progress handler), so leaks in nave's conversion are still reported (docs/fuzzing.md: the
// long run turns leak detection off for speed and runs its corpus again with it on).
namespace Assimp {

void aiAssertViolation(const char* expression, const char* file, int line);

void aiAssertViolation(const char* expression, const char* file, int line) {
    throw std::runtime_error("ai_assert failure in " + std::string(file) + "(" +
                             std::to_string(line) + "): " + expression);
}

}  // namespace Assimp

extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace nave::preprocess;
    const nave::fuzz::AssimpFuzzInput input = nave::fuzz::SplitAssimpFuzzInput(data, size);
    const auto path = nave::fuzz::WriteInput(input.name, input.bytes);
    nave::StatusOr<ImportedModel> model = ReadWithAssimpInProcess(path);
    if (!model.ok()) return 0;
    nave::StatusOr<ImportedModel> back =
        DecodeImportedModel(EncodeImportedModel(*model), input.name);
    if (!back.ok()) std::abort();  // what one side encodes the other must decode
    nave::fuzz::Drain(std::unique_ptr<TriangleSource>(
        new IndexedMeshSource(input.name, "unknown", std::move(back->meshes),
                              std::move(back->materials), ImportWarnings())));
    return 0;
}
