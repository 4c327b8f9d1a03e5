#pragma once
// Recomputes every checksum of a (damaged) store in place: each brick section's in its directory
// entry, each level section's in the levels table, each piece of the medium's in the medium table,
// each table's in the header, the header's own, and the header's file size. Random damage almost
// never gets past the checksums; resealed, it reaches the decoders behind them (directory, tree,
// materials, Draco, LZ4), which must hold on their own. Offsets that point outside the bytes are
// left alone: the reader must refuse those anyway.

#include <string>

namespace nave::fuzz {

void ResealStore(std::string& bytes);

}  // namespace nave::fuzz
