#pragma once
// A resident brick mesh holds exactly the arrays of the store's mesh it was made from.

#include <gtest/gtest.h>

#include <span>
#include <vector>

#include "src/render/bricks/resident_mesh.h"
#include "store/brick_mesh.h"

namespace nave::render::testing {

template <typename T>
std::vector<T> ToVector(std::span<const T> s) {
    return std::vector<T>(s.begin(), s.end());
}

inline void ExpectSameMesh(const ResidentMesh& a, const store::BrickMesh& b) {
    EXPECT_EQ(ToVector(a.positions), b.positions);
    EXPECT_EQ(ToVector(a.normals), b.normals);
    EXPECT_EQ(ToVector(a.uvs), b.uvs);
    EXPECT_EQ(ToVector(a.indices), b.indices);
    EXPECT_EQ(ToVector(a.material_ids), b.material_ids);
}

}  // namespace nave::render::testing
