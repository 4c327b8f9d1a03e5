#pragma once
// The model's own description of a material, as the CAD export gave it (MTL, glTF...). The store
// keeps it verbatim; mapping these names to spectral materials is the renderer's business (scene
// config).

#include <array>
#include <map>
#include <string>

namespace nave::store {

struct MaterialRecord {
    std::string name;                                ///< unique within a store
    std::array<float, 3> diffuse{0.8f, 0.8f, 0.8f};  ///< MTL Kd / glTF baseColorFactor (linear RGB)
    std::array<float, 3> specular{0.f, 0.f, 0.f};    ///< MTL Ks
    std::array<float, 3> emission{0.f, 0.f, 0.f};    ///< MTL Ke / glTF emissiveFactor
    float ior = 1.5f;                                ///< MTL Ni
    float opacity = 1.f;                             ///< MTL d (1 - Tr)
    float shininess = 0.f;                           ///< MTL Ns
    float metallic = 0.f;                            ///< glTF metallicFactor
    float roughness = 1.f;                           ///< glTF roughnessFactor
    /// Where an alpha texture (MTL map_d, glTF alphaMode MASK) is below this, the surface is cut
    /// out (glTF alphaCutoff; 0.5 for MTL and by default). Format 1.1; 1.0 stores read as 0.5.
    float alpha_cutoff = 0.5f;
    /// Texture slots by their source name ("map_Kd", "map_d", "bump", "baseColorTexture"...) to a
    /// path relative to the store file, or to the source model's directory when not yet converted.
    std::map<std::string, std::string> textures;
    bool operator==(const MaterialRecord&) const = default;
};

}  // namespace nave::store
