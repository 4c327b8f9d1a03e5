// A development tool, not a test: renders quick previews of the procedural abbey (primary rays with
// Embree, material colour times a head-light term) to check its geometry and the camera spots of
// docs/abbey.md. Usage: abbey_preview DETAIL OUT_DIR

#include <OpenImageIO/imageio.h>
#include <embree3/rtcore.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "preprocess/abbey/abbey_plan.h"
#include "preprocess/abbey/abbey_source.h"
#include "src/core/sampling.h"

using namespace nave;

struct View {
    const char* name;
    Vec3f eye, target;
    float fov_deg;
};

int main(int argc, char** argv) {
    double detail = argc > 1 ? std::atof(argv[1]) : 0.25;
    std::string out = argc > 2 ? argv[2] : ".";
    auto source = preprocess::MakeAbbeySource(detail);
    std::vector<float> verts;
    std::vector<unsigned> mats, part_of;
    // Generated part by part here (not through the source) to know which part each triangle comes
    // from.
    auto parts = preprocess::abbey::AbbeyParts(preprocess::abbey::Detail(detail));
    unsigned current = 0;
    preprocess::abbey::Emitter em(
        [&](std::vector<preprocess::Triangle>& batch) {
            for (const auto& t : batch) {
                for (const auto& p : t.p) verts.insert(verts.end(), {p.x, p.y, p.z});
                mats.push_back(t.material);
                part_of.push_back(current);
            }
        },
        1);
    for (current = 0; current < parts.size(); ++current) parts[current].emit(em);
    size_t n = mats.size();
    std::printf("%zu triangles\n", n);
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, verts.data(), 0, 12,
                               3 * n);
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n));
    for (size_t i = 0; i < 3 * n; ++i) ib[i] = unsigned(i);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    const auto& materials = source->materials();
    const View views[] = {
        {"exterior_sw", Vec3f(-35, -60, 45), Vec3f(45, 0, 12), 50},
        {"exterior_ne", Vec3f(130, 55, 40), Vec3f(60, 0, 12), 50},
        {"nave_east", Vec3f(4, 0, 1.7f), Vec3f(60, 0, 12), 70},
        {"crossing_up", Vec3f(62.5f, -4, 1.7f), Vec3f(62.5f, 0.5f, 28), 90},
        {"choir", Vec3f(70, 3, 1.7f), Vec3f(92, 0, 9), 75},
        {"aisle", Vec3f(2, 10, 1.7f), Vec3f(50, 10, 6), 70},
        {"plan_top", Vec3f(50, 0, 200), Vec3f(50, 0.01f, 0), 40},
    };
    const int w = 800, h = 500;
    for (const View& v : views) {
        std::vector<unsigned char> img(w * h * 3);
        std::map<unsigned, int> back;
        Vec3f fwd = Normalize(v.target - v.eye);
        Vec3f right = Normalize(Cross(fwd, Vec3f(0, 0, 1)));
        Vec3f up = Cross(right, fwd);
        float scale = std::tan(v.fov_deg * kPi / 360);
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                float sx = (2 * (x + 0.5f) / w - 1) * scale,
                      sy = (1 - 2 * (y + 0.5f) / h) * scale * h / w;
                Vec3f d = Normalize(fwd + right * sx + up * sy);
                RTCIntersectContext ctx;
                rtcInitIntersectContext(&ctx);
                RTCRayHit rh{};
                rh.ray.org_x = v.eye.x;
                rh.ray.org_y = v.eye.y;
                rh.ray.org_z = v.eye.z;
                rh.ray.dir_x = d.x;
                rh.ray.dir_y = d.y;
                rh.ray.dir_z = d.z;
                rh.ray.tnear = 0;
                rh.ray.tfar = 1e30f;
                rh.ray.mask = ~0u;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &ctx, &rh);
                float r = 0.55f, gg = 0.7f, b = 0.95f;  // sky
                if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
                    Vec3f nn = Normalize(Vec3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
                    const auto& m = materials[mats[rh.hit.primID]];
                    bool front = Dot(nn, d) < 0;
                    float shade =
                        0.25f + 0.75f * std::abs(Dot(nn, Normalize(Vec3f(0.3f, -0.5f, 0.8f))));
                    shade *= 0.6f + 0.4f * std::abs(Dot(nn, d));
                    r = m.diffuse[0] * shade;
                    gg = m.diffuse[1] * shade;
                    b = m.diffuse[2] * shade;
                    if (!front) {  // back faces in magenta: winding errors show
                        r = 1;
                        gg = 0;
                        b = 1;
                        if (back[mats[rh.hit.primID]]++ % 5000 == 0 &&
                            std::getenv("NAVE_PREVIEW_DEBUG")) {
                            Vec3f hp = v.eye + d * rh.ray.tfar;
                            std::printf(
                                "  back face at (%.2f %.2f %.2f) Ng (%.2f %.2f %.2f) of %s\n", hp.x,
                                hp.y, hp.z, nn.x, nn.y, nn.z,
                                parts[part_of[rh.hit.primID]].name.c_str());
                        }
                    }
                }
                unsigned char* px = &img[3 * (y * w + x)];
                px[0] = (unsigned char)(std::min(1.f, std::pow(r, 1 / 2.2f)) * 255);
                px[1] = (unsigned char)(std::min(1.f, std::pow(gg, 1 / 2.2f)) * 255);
                px[2] = (unsigned char)(std::min(1.f, std::pow(b, 1 / 2.2f)) * 255);
            }
        }
        std::string path = out + "/" + v.name + ".png";
        auto file = OIIO::ImageOutput::create(path);
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
        file->open(path, spec);
        file->write_image(OIIO::TypeDesc::UINT8, img.data());
        file->close();
        std::printf("wrote %s", path.c_str());
        for (auto [m, count] : back)
            std::printf(" [back faces of %s: %d px]", materials[m].name.c_str(), count);
        std::printf("\n");
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
}
