// A store damaged anywhere and rendered: one byte flipped at positions spread over every section of
// a small store (header, the five tables, each brick's mesh section and occupancy grid), each
// rendered as `nave render` does (StoreBrickSource, scene, streams). Each must end in an error
// naming the store and the section the byte is in, or in the very image of the undamaged store;
// never a crash or a hang. A few flips also go through the `nave` executable, for its exit code and
// message. scripts/corrupt_store_trials.sh runs every byte of the file the same way, for longer.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <map>

#include "common/run_nave.h"
#include "render_test_util.h"
#include "src/core/file.h"
#include "src/core/log.h"
#include "src/core/progress.h"
#include "src/render/bricks/store_brick_source.h"
#include "store/store_format.h"
#include "store/store_reader.h"
#include "store/testing/store_testing.h"

namespace nave::render {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;

// A camera above the whole wavy surface (10 x 10 m, cut into 2 x 2 bricks) so every brick is hit;
// one thread, so that an undamaged store renders the same image bit for bit each time.
constexpr const char* kConfig = R"(
[camera]
position = [5.0, 5.0, 14.0]
look_at = [5.0, 5.0, 0.0]
up = [0, 1, 0]
fov_deg = 50
resolution = [12, 12]
[sky]
radiance = 1.0
[materials.default]
reflectance = 0.5
[render]
spp = 1
max_depth = 2
seed = 3
threads = 1
)";

// A section of the file and what an error about it must say.
struct Section {
    std::string name;                                         // for messages
    uint64_t begin, end;                                      // byte range
    std::vector<std::string> says;                            // the error must contain one of these
    std::vector<StatusCode> codes = {StatusCode::kDataLoss};  // and have one of these codes
};

class CorruptStoreRender : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        dir_ = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                         ("nave_corrupt_render_" + std::to_string(::getpid())));
        std::filesystem::create_directories(*dir_);
        log::SetLevel(log::Level::kError);  // hundreds of renders: no progress lines
        ProgressBar::SetEnabled(false);
        const store::BrickMesh mesh = store::testing::MakeSurface({.quads_x = 12, .quads_y = 12});
        auto written =
            store::testing::WriteGridStore(Good(), mesh, store::testing::MakeMaterials(3),
                                           {2, 2, 1}, store::GlobalGrid{{0, 0, 0}, 1e-3});
        ASSERT_TRUE(written.ok()) << written.status().ToString();
        auto config = ParseSceneConfig(kConfig, "corrupt.toml");
        ASSERT_TRUE(config.ok()) << config.status().ToString();
        config_ = new SceneConfig(*config);
        auto device = EmbreeDevice::Create();
        ASSERT_TRUE(device.ok());
        device_ = new std::shared_ptr<EmbreeDevice>(*device);
    }
    static void TearDownTestSuite() {
        std::filesystem::remove_all(*dir_);
        delete dir_;
        delete config_;
        delete device_;
    }
    static std::filesystem::path Good() { return *dir_ / "good.nave"; }

    // Renders the store at `path` as `nave render` does; the image's pixels, or the first error.
    static StatusOr<std::vector<Vec3d>> RenderStore(const std::filesystem::path& path) {
        NAVE_ASSIGN_OR_RETURN(auto source, StoreBrickSource::Open(path, *device_));
        NAVE_ASSIGN_OR_RETURN(auto scene, testing::BuildTestScene(std::move(source), *config_));
        const testing::RenderResult r = scene->Run();
        NAVE_RETURN_IF_ERROR(r.status);
        std::vector<Vec3d> pixels(r.film->pixel_count());
        for (size_t p = 0; p < pixels.size(); ++p) pixels[p] = r.film->PixelXYZ(uint32_t(p));
        return pixels;
    }

    // The sections of the good store, from its own header and directory.
    static std::vector<Section> Sections() {
        auto store = store::Store::Open(Good());
        EXPECT_TRUE(store.ok());
        const std::string bytes = ReadFileToString(Good()).value();
        const auto header = store::format::DecodeHeader(bytes, "good", bytes.size()).value();
        // The magic and the major version are read before the header's checksum (another format or
        // version must be told apart from damage): their own errors.
        std::vector<Section> sections = {
            {"magic", 0, 8, {"not a nave store: magic"}, {StatusCode::kUnsupported}},
            // A major still in the readable range fails the header's checksum instead.
            {"major version",
             8,
             10,
             {"store format version", "header @0x0: checksum"},
             {StatusCode::kUnsupported, StatusCode::kDataLoss}},
            {"header", 10, header.header_bytes, {"header"}}};
        for (const auto& [name, ref] :
             {std::pair{"provenance", header.provenance}, std::pair{"directory", header.directory},
              std::pair{"tree", header.tree}, std::pair{"materials", header.materials},
              std::pair{"occupancy", header.occupancy}}) {
            sections.push_back(
                {name, ref.offset, ref.offset + ref.length, {std::string(name) + " table"}});
        }
        for (const store::BrickInfo& b : (*store)->bricks()) {
            sections.push_back({"brick " + std::to_string(b.id),
                                b.mesh.offset,
                                b.mesh.offset + b.mesh.length,
                                {"brick " + std::to_string(b.id)}});
            if (b.side.length > 0) {
                sections.push_back({"brick " + std::to_string(b.id) + " side",
                                    b.side.offset,
                                    b.side.offset + b.side.length,
                                    {"brick " + std::to_string(b.id)}});
            }
            // Read when the store opens for a render: a damaged grid stops it, naming the brick.
            if (b.occupancy.length > 0) {
                sections.push_back({"brick " + std::to_string(b.id) + " occupancy",
                                    b.occupancy.offset,
                                    b.occupancy.offset + b.occupancy.length,
                                    {"brick " + std::to_string(b.id)}});
            }
        }
        return sections;
    }

    static inline std::filesystem::path* dir_ = nullptr;
    static inline SceneConfig* config_ = nullptr;
    static inline std::shared_ptr<EmbreeDevice>* device_ = nullptr;
};

TEST_F(CorruptStoreRender, TheSectionsCoverTheWholeFile) {
    std::vector<Section> sections = Sections();
    std::sort(sections.begin(), sections.end(),
              [](const Section& a, const Section& b) { return a.begin < b.begin; });
    uint64_t at = 0;
    for (const Section& s : sections) {
        EXPECT_EQ(s.begin, at) << s.name << ": a gap or an overlap before it";
        at = s.end;
    }
    EXPECT_EQ(at, std::filesystem::file_size(Good()));
    // magic, version, header, 5 tables, 4 bricks and their occupancy grids
    EXPECT_GE(sections.size(), 16u);
}

TEST_F(CorruptStoreRender, EveryFlippedByteIsAnErrorNamingItsSectionOrTheSameImage) {
    auto reference = RenderStore(Good());
    ASSERT_TRUE(reference.ok()) << reference.status().ToString();
    // Rendering twice gives the same image: "identical" below means the flip changed nothing.
    ASSERT_EQ(*RenderStore(Good()), *reference);
    double lit = 0;
    for (const Vec3d& p : *reference) lit += p.y;
    ASSERT_GT(lit, 0) << "the camera must see the surface";

    const std::string good = ReadFileToString(Good()).value();
    const std::filesystem::path bad = *dir_ / "bad.nave";
    std::map<std::string, int> errors, same;
    for (const Section& s : Sections()) {
        // Its first and last bytes, and about 64 between, spread evenly.
        const uint64_t step = std::max<uint64_t>(1, (s.end - s.begin) / 64);
        std::vector<uint64_t> offsets;
        for (uint64_t o = s.begin; o < s.end; o += step) offsets.push_back(o);
        offsets.push_back(s.end - 1);
        for (uint64_t offset : offsets) {
            SCOPED_TRACE(s.name + " byte " + std::to_string(offset));
            std::string bytes = good;
            bytes[offset] = char(bytes[offset] ^ (1 << (offset % 8)));
            std::ofstream(bad, std::ios::binary | std::ios::trunc) << bytes;
            auto image = RenderStore(bad);
            if (image.ok()) {
                EXPECT_EQ(*image, *reference) << "a damaged store rendered a different image";
                ++same[s.name];
                continue;
            }
            ++errors[s.name];
            EXPECT_THAT(s.codes, Contains(image.status().code())) << image.status().ToString();
            EXPECT_THAT(image.status().message(), HasSubstr(bad.string()));
            EXPECT_TRUE(std::any_of(s.says.begin(), s.says.end(),
                                    [&](const std::string& w) {
                                        return image.status().message().find(w) !=
                                               std::string::npos;
                                    }))
                << image.status().message() << "\n  names not " << s.says.front();
        }
    }
    // Every byte of this format is under a checksum: no flip may pass unnoticed.
    int flips = 0;
    for (const auto& [name, n] : errors) flips += n;
    for (const auto& [name, n] : same)
        ADD_FAILURE() << n << " flips in " << name << " went unnoticed";
    EXPECT_GT(flips, 500);
    EXPECT_GE(errors.size(), 11u);
}

TEST_F(CorruptStoreRender, NaveRenderExitsWithAnErrorNamingTheBrick) {
    const std::string good = ReadFileToString(Good()).value();
    const std::filesystem::path config = *dir_ / "corrupt.toml";
    std::ofstream(config) << kConfig;
    for (const Section& s : Sections()) {
        if (s.name != "header" && s.name != "directory" && s.name != "brick 1" &&
            s.name != "brick 3")
            continue;
        SCOPED_TRACE(s.name);
        std::string bytes = good;
        const uint64_t offset = (s.begin + s.end) / 2;
        bytes[offset] = char(bytes[offset] ^ 0x10);
        const std::filesystem::path bad = *dir_ / "bad_cli.nave";
        std::ofstream(bad, std::ios::binary | std::ios::trunc) << bytes;
        const std::filesystem::path out = *dir_ / "out.exr";
        const auto r = test::RunNave("render " + bad.string() + " -c " + config.string() + " -o " +
                                     out.string() + " -q");
        EXPECT_EQ(r.exit_code, 1) << r.output;
        EXPECT_THAT(r.output, HasSubstr("nave: error: "));
        EXPECT_THAT(r.output, HasSubstr(bad.string()));
        EXPECT_THAT(r.output, HasSubstr(s.says.front()));
        EXPECT_FALSE(std::filesystem::exists(out)) << "no image from a damaged store";
    }
}

}  // namespace
}  // namespace nave::render
