#include "preprocess/abbey/materials.h"

#include <string_view>

#include "preprocess/abbey/glass_textures.h"

namespace nave::preprocess::abbey {

std::vector<store::MaterialRecord> AbbeyMaterials() {
    // Preview colours only (linear RGB for viewers of the OBJ); the renderer maps names to spectral
    // data.
    struct Def {
        const char* name;
        float r, g, b, opacity, ior;
    };
    const Def defs[kMaterialCount] = {
        {"limestone", 0.72f, 0.68f, 0.60f, 1.f, 1.5f},
        {"limestone_dark", 0.55f, 0.52f, 0.46f, 1.f, 1.5f},
        {"floor_tile_light", 0.78f, 0.74f, 0.66f, 1.f, 1.5f},
        {"floor_tile_dark", 0.30f, 0.16f, 0.10f, 1.f, 1.5f},
        {"glass_clear", 0.85f, 0.88f, 0.85f, 0.1f, 1.52f},
        {"glass_blue", 0.10f, 0.20f, 0.70f, 0.2f, 1.52f},
        {"glass_red", 0.70f, 0.08f, 0.06f, 0.2f, 1.52f},
        {"glass_yellow", 0.80f, 0.65f, 0.10f, 0.2f, 1.52f},
        {"glass_green", 0.10f, 0.50f, 0.15f, 0.2f, 1.52f},
        {"lead", 0.25f, 0.25f, 0.27f, 1.f, 1.5f},
        {"wood", 0.35f, 0.22f, 0.12f, 1.f, 1.5f},
        {"roof_slate", 0.20f, 0.21f, 0.24f, 1.f, 1.5f},
    };
    std::vector<store::MaterialRecord> out;
    for (const Def& d : defs) {
        store::MaterialRecord m;
        m.name = d.name;
        m.diffuse = {d.r, d.g, d.b};
        m.opacity = d.opacity;
        m.ior = d.ior;
        // Glass carries its spectral transmittance map, written beside the model by
        // WriteGlassTextures.
        if (std::string_view(d.name).rfind("glass_", 0) == 0)
            m.textures[kTransmittanceSlot] = GlassTextureName(d.name);
        out.push_back(m);
    }
    return out;
}

}  // namespace nave::preprocess::abbey
