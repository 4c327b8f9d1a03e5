// The store reader: header, tables, brick decode (Draco, LZ4). The first input byte picks the mode:
// even, the rest is the file as it is (checksums as the fuzzer left them: the checks in front must
// refuse cleanly); odd, the rest is resealed first (store_reseal.h), to reach the decoders behind
// the checksums. Every brick is then read and verified, as `nave verify` does.

#include "fuzz_file.h"
#include "store/store_reader.h"
#include "store_reseal.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
    if (data[0] & 1) nave::fuzz::ResealStore(bytes);
    auto store = nave::store::Store::Open(nave::fuzz::WriteInput("fuzz.nave", bytes));
    if (!store.ok()) return 0;
    for (uint32_t b = 0; b < (*store)->bricks().size(); ++b) (void)(*store)->VerifyBrick(b);
    return 0;
}
