#include "preprocess/triangle_source.h"

namespace nave::preprocess {

StatusOr<std::vector<Triangle>> ReadAll(TriangleSource& source) {
    std::vector<Triangle> all, batch;
    while (true) {
        NAVE_ASSIGN_OR_RETURN(bool more, source.Next(batch, 1 << 16));
        if (!more) break;
        all.insert(all.end(), batch.begin(), batch.end());
    }
    return all;
}

}  // namespace nave::preprocess
