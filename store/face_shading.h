#pragma once
// How each face of a brick is shaded once stored (internal to nave_store; docs/store-format.md,
// "Shading"): with normals stored in Draco, with its geometric normal (flat), or with normals the
// decoder recomputes from the decoded positions (derived). Flat and derived faces store no normals,
// and their corners join by grid point, so they cost a fraction of a stored face.

#include <array>
#include <cstdint>
#include <vector>

#include "src/core/vecmath.h"
#include "store/brick_mesh.h"
#include "store/grid.h"

namespace nave::store::codec {

/// A face's shading, the low two bits of its material attribute value (format 3.0).
enum Shading : uint8_t {
    kShadingStored = 0,  ///< normals in Draco; counts towards its smoothing group's derived normals
    kShadingFlat = 1,    ///< shaded with its geometric normal (decoded normals are zero)
    kShadingDerived = 2,      ///< normals recomputed from its smoothing group's faces
    kShadingStoredApart = 3,  ///< normals in Draco; in no smoothing group
};
/// Whether a face of this shading keeps its normals in Draco.
inline bool StoresNormals(int shading) {
    return shading == kShadingStored || shading == kShadingStoredApart;
}
/// Smoothing groups at one grid point: the next two bits of the material attribute value.
inline constexpr int kSmoothingGroups = 4;

/// A face is flat when every corner normal is within 0.8 degrees of its geometric normal (cos >=
/// 0.9999): ten-bit octahedral normals, what stored faces keep, already err by up to ~0.2 degrees.
inline constexpr double kFlatCosine = 0.9999;

/// A face's contribution to the derived normal at each of its corners: its unit geometric normal
/// times the corner's angle (G. Thuermer, C. Wuethrich, "Computing vertex normals from polygonal
/// facets", JGT 3(1), 1998: unlike area weights, angle weights do not depend on how a polygon was
/// cut into triangles). Zero for a degenerate face.
std::array<Vec3d, 3> AngleWeightedNormals(const Vec3i& a, const Vec3i& b, const Vec3i& c);

/// The shading and smoothing group of each face of a brick being encoded.
struct FaceShading {
    std::vector<uint8_t> shading;  ///< a Shading per face
    std::vector<uint8_t> group;    ///< smoothing group in [0, kSmoothingGroups) (0 when flat)
    size_t flat_count = 0, stored_count = 0;
};

/// Grid points strictly inside this box have all their faces in the brick (bricks hold every
/// triangle that overlaps their cell).
using Bounds3i = Bounds3<int32_t>;

/// Chooses each face's shading. `faces` are the brick's faces (indices into `mesh`), `grid_point`
/// each vertex's grid position and `position_id` a dense id per distinct grid position. Only faces
/// whose corners lie strictly inside `complete_within` may be derived: their derived normals sum
/// whole fans, the same in every brick that holds the face, so the image does not depend on how
/// the model was cut.
///
/// Derived normals: a corner's derived normal is the angle-weighted sum of the normals of the
/// faces, stored or derived, that have a corner on the same grid point with the same material and
/// smoothing group. Smoothing groups keep the sides of a crease apart: faces joined through shared
/// input vertices form a patch (inputs split vertices where the normal jumps), and patches that
/// meet at a grid point get different groups. A face is derived when all three derived normals
/// are within `max_error_deg` degrees of its given ones; otherwise it is stored, and still counts,
/// so one pass decides. The decoder recomputes the same sums (brick_codec.cpp).
FaceShading ChooseFaceShading(const BrickMesh& mesh, const std::vector<uint32_t>& faces,
                              const std::vector<Vec3i>& grid_point,
                              const std::vector<uint32_t>& position_id,
                              const Bounds3i& complete_within, double max_error_deg);

}  // namespace nave::store::codec
