// The partition and the store it writes: the exact triangle/box test, bins round trip, and stores
// built from closed meshes hold exactly the input's triangles (duplicates aside) and let no ray
// through between bricks.

#include <embree3/rtcore.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "preprocess/abbey/abbey_source.h"
#include "preprocess/partition/bin_file.h"
#include "preprocess/partition/partitioner.h"
#include "preprocess/partition/temp_dir.h"
#include "preprocess/partition/triangle_box.h"
#include "preprocess/preprocess.h"
#include "src/core/hash.h"
#include "src/core/progress.h"
#include "store/store_reader.h"
#include "test_util.h"

namespace nave::preprocess {
namespace {

using ::testing::HasSubstr;

TEST(TriangleBox, SeparatingAxes) {
    Bounds3d box(Vec3d(0, 0, 0), Vec3d(1, 1, 1));
    // Inside, outside on one axis, and touching a face.
    EXPECT_TRUE(TriangleOverlapsBox(
        {Vec3f(0.2f, 0.2f, 0.5f), Vec3f(0.8f, 0.2f, 0.5f), Vec3f(0.5f, 0.8f, 0.5f)}, box));
    EXPECT_FALSE(TriangleOverlapsBox({Vec3f(2, 0, 0), Vec3f(3, 0, 0), Vec3f(2, 1, 0)}, box));
    EXPECT_TRUE(TriangleOverlapsBox({Vec3f(1, 0, 0), Vec3f(2, 0, 0), Vec3f(1, 1, 0)}, box));
    // A big triangle through the box with no vertex inside it.
    EXPECT_TRUE(TriangleOverlapsBox(
        {Vec3f(-10, -10, 0.5f), Vec3f(10, -10, 0.5f), Vec3f(0, 10, 0.5f)}, box));
    // Its bounding box overlaps the box but the triangle passes by a corner: only an edge axis
    // separates.
    EXPECT_FALSE(TriangleOverlapsBox(
        {Vec3f(0.9f, 1.6f, 0.5f), Vec3f(1.6f, 0.9f, 0.5f), Vec3f(1.6f, 1.6f, 0.5f)}, box));
    EXPECT_TRUE(TriangleOverlapsBox(
        {Vec3f(0.3f, 1.6f, 0.5f), Vec3f(1.6f, 0.3f, 0.5f), Vec3f(1.6f, 1.6f, 0.5f)}, box));
    // A tilted plane crossing the box's bounding region but missing the box (plane axis separates).
    EXPECT_FALSE(
        TriangleOverlapsBox({Vec3f(-5, -5, 3.5f), Vec3f(5, -5, 13.5f), Vec3f(-5, 5, 3.5f)}, box));
}

TEST(BinFile, RoundTripWithAndWithoutAttributes) {
    auto dir = testing::MakeTempDir("bin");
    std::vector<Triangle> in;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-100, 100);
    for (int i = 0; i < 50000; ++i) {
        Triangle t;
        for (auto& p : t.p) p = Vec3f(u(rng), u(rng), u(rng));
        t.material = uint32_t(i % 37);
        t.has_normals = i % 3 == 0;
        t.has_uvs = i % 5 == 0;
        if (t.has_normals) t.n = {Vec3f(0, 0, 1), Vec3f(0, 1, 0), Vec3f(1, 0, 0)};
        if (t.has_uvs) t.uv = {{{0.1f, 0.2f}, {0.3f, 0.4f}, {0.5f, float(i)}}};
        in.push_back(t);
    }
    {
        auto w = BinWriter::Create(dir / "a.lz4", 4096);
        ASSERT_TRUE(w.ok());
        for (const auto& t : in) ASSERT_TRUE((*w)->Append(t).ok());
        ASSERT_TRUE((*w)->Close().ok());
    }
    auto r = BinReader::Open(dir / "a.lz4");
    ASSERT_TRUE(r.ok());
    std::vector<Triangle> out;
    while (true) {
        auto more = (*r)->Read(out, 777);
        ASSERT_TRUE(more.ok());
        if (!*more) break;
    }
    ASSERT_EQ(out.size(), in.size());
    for (size_t i = 0; i < in.size(); ++i) {
        ASSERT_EQ(out[i].p, in[i].p);
        ASSERT_EQ(out[i].material, in[i].material);
        ASSERT_EQ(out[i].has_normals, in[i].has_normals);
        ASSERT_EQ(out[i].has_uvs, in[i].has_uvs);
        if (in[i].has_normals) {
            ASSERT_EQ(out[i].n, in[i].n);
        }
        if (in[i].has_uvs) {
            ASSERT_EQ(out[i].uv, in[i].uv);
        }
    }
    std::filesystem::remove_all(dir);
}

// A closed icosphere of radius `r` subdivided `levels` times (20 * 4^levels triangles), outward
// winding, written as OBJ.
void WriteIcosphere(const std::filesystem::path& path, int levels, double r) {
    const double t = (1 + std::sqrt(5.0)) / 2;
    std::vector<Vec3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                            {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                            {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::array<int, 3>> f = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (auto& p : v) p = Normalize(p);
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<int, int>, int> mid;
        auto midpoint = [&](int a, int b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(Normalize(v[a] + v[b]));
            return mid[key] = int(v.size() - 1);
        };
        std::vector<std::array<int, 3>> next;
        for (auto [a, b, c] : f) {
            int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            next.insert(next.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
        }
        f = std::move(next);
    }
    std::FILE* out = std::fopen(path.c_str(), "w");
    for (auto& p : v)
        std::fprintf(out, "v %.9g %.9g %.9g\n", p.x * r + 3, p.y * r - 2, p.z * r + 1);
    for (auto [a, b, c] : f) std::fprintf(out, "f %d %d %d\n", a + 1, b + 1, c + 1);
    std::fclose(out);
}

using QTri = std::array<Vec3i, 3>;
struct QTriLess {
    bool operator()(const QTri& a, const QTri& b) const {
        for (int j = 0; j < 3; ++j) {
            for (int k = 0; k < 3; ++k) {
                if (a[j][k] != b[j][k]) return a[j][k] < b[j][k];
            }
        }
        return false;
    }
};
// Rotates the corners so that the smallest comes first (keeping the winding).
QTri Canonical(QTri q) {
    QTriLess less;
    auto key = [](const Vec3i& v) { return std::array<int32_t, 3>{v.x, v.y, v.z}; };
    int first = 0;
    for (int j = 1; j < 3; ++j) {
        if (key(q[j]) < key(q[first])) first = j;
    }
    (void)less;
    return {q[first], q[(first + 1) % 3], q[(first + 2) % 3]};
}

class PartitionedSphere : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        scratch_ = std::make_unique<test::ScratchDir>(testing::MakeTempDir("sphere"));
        dir_ = scratch_->path();
        WriteIcosphere(dir_ / "sphere.obj", 5, 2.0);  // 20480 triangles
    }
    static void TearDownTestSuite() { scratch_.reset(); }

    /// Levels of 2 % and 8 % of a brick's extent: an icosphere brick of ~1000 triangles keeps
    /// fewer than a fifth of them at the first.
    static inline const std::vector<double> kTestLevelErrors = {0.02, 0.08};
    static PreprocessStats Run(const std::filesystem::path& out, uint64_t memory, int threads) {
        PreprocessOptions o;
        o.inputs = {dir_ / "sphere.obj"};
        o.output = out;
        o.brick_triangles = 1000;
        o.memory_bytes = memory;
        o.threads = threads;
        o.encode.levels.relative_errors = kTestLevelErrors;
        auto stats = RunPreprocess(o);
        EXPECT_TRUE(stats.ok()) << stats.status().ToString();
        return stats.ok() ? *stats : PreprocessStats{};
    }
    static inline std::unique_ptr<test::ScratchDir> scratch_;
    static inline std::filesystem::path dir_;
};

// Without --brick-triangles, a budget too small for million-triangle bricks gets smaller bricks
// instead of a refusal: here about 5 000 triangles (48 MiB fixed + 5 000 x 5/4 x 600 bytes of
// encoding work).
TEST_F(PartitionedSphere, SmallBudgetWithoutBrickSizeChoosesSmallerBricks) {
    const auto out = dir_ / "auto.nave";
    PreprocessOptions o;
    o.inputs = {dir_ / "sphere.obj"};
    o.output = out;
    o.memory_bytes = (48ull << 20) + 5000 * 5 / 4 * 600;
    auto stats = RunPreprocess(o);
    ASSERT_TRUE(stats.ok()) << stats.status().ToString();
    auto st = store::Store::Open(out);
    ASSERT_TRUE(st.ok()) << st.status().ToString();
    EXPECT_GE((*st)->bricks().size(), 3u) << "20 480 triangles in bricks of about 5 000";
    for (const store::BrickInfo& b : (*st)->bricks()) {
        EXPECT_LE(b.triangle_count, 5000u * 5 / 4 + 500) << "brick " << b.id;
    }
    std::filesystem::remove(out);
}

std::set<QTri, QTriLess> StoreTriangles(const store::Store& s, uint64_t* references) {
    std::set<QTri, QTriLess> all;
    *references = 0;
    for (uint32_t b = 0; b < s.bricks().size(); ++b) {
        auto mesh = s.ReadBrick(b);
        EXPECT_TRUE(mesh.ok()) << mesh.status().ToString();
        if (!mesh.ok()) continue;
        for (size_t t = 0; t < mesh->TriangleCount(); ++t) {
            QTri q;
            for (int j = 0; j < 3; ++j)
                q[j] = s.header().grid.Quantize(mesh->positions[mesh->indices[3 * t + j]]);
            all.insert(Canonical(q));
            ++*references;
        }
    }
    return all;
}

// Brick ids follow the brick tree's leaves, not the order threads finish them in: one thread and
// two give the same directory (cells, counts, payload checksums) and the same tree.
TEST_F(PartitionedSphere, BrickIdsDoNotDependOnTheThreadCount) {
    Run(dir_ / "one.nave", 0, 1);
    Run(dir_ / "two.nave", 0, 2);
    auto one = store::Store::Open(dir_ / "one.nave");
    auto two = store::Store::Open(dir_ / "two.nave");
    ASSERT_TRUE(one.ok() && two.ok());
    const auto& a = (*one)->bricks();
    const auto& b = (*two)->bricks();
    ASSERT_EQ(a.size(), b.size());
    ASSERT_GE(a.size(), 16u);
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].cell.min, b[i].cell.min) << "brick " << i;
        EXPECT_EQ(a[i].cell.max, b[i].cell.max) << "brick " << i;
        EXPECT_EQ(a[i].triangle_count, b[i].triangle_count) << "brick " << i;
        EXPECT_EQ(a[i].mesh.checksum, b[i].mesh.checksum) << "brick " << i;
        EXPECT_EQ(a[i].mesh.offset, b[i].mesh.offset) << "brick " << i;
        ASSERT_EQ(a[i].levels.size(), b[i].levels.size()) << "brick " << i;
        for (size_t k = 0; k < a[i].levels.size(); ++k) {
            EXPECT_EQ(a[i].levels[k].mesh.checksum, b[i].levels[k].mesh.checksum)
                << "brick " << i << " level " << k + 1;
            EXPECT_EQ(a[i].levels[k].error, b[i].levels[k].error);
        }
    }
    for (int k = 0; k < 100; ++k) {
        const Vec3f p =
            (*one)->header().bounds.min +
            ((*one)->header().bounds.max - (*one)->header().bounds.min) * (float(k) / 100.f);
        EXPECT_EQ((*one)->tree().Locate(p), (*two)->tree().Locate(p));
    }
}

// Preprocess stores levels of detail when asked (each brick of about 1000 triangles gets one or
// two) and none by default; the summary and the provenance say so.
TEST_F(PartitionedSphere, LevelsWhenAskedNoneByDefault) {
    const PreprocessStats with = Run(dir_ / "levels.nave", 0, 2);
    auto store = store::Store::Open(dir_ / "levels.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    uint64_t level_triangles = 0;
    for (const store::BrickInfo& b : (*store)->bricks()) {
        ASSERT_GE(b.levels.size(), 1u) << "brick " << b.id;
        EXPECT_LT(b.levels[0].triangle_count, b.triangle_count / 2) << "brick " << b.id;
        if (b.levels.size() > 1) {
            EXPECT_GT(b.levels[1].error, b.levels[0].error) << "brick " << b.id;
        }
        EXPECT_TRUE((*store)->VerifyBrick(b.id).ok());
        level_triangles += b.levels[0].triangle_count;
    }
    ASSERT_GE(with.level_triangles.size(), 1u);
    EXPECT_EQ(with.level_triangles[0], level_triangles);
    EXPECT_THAT(FormatSummary(with), HasSubstr("level 1: "));
    EXPECT_THAT((*store)->header().provenance.options, HasSubstr("level-errors=0.02,0.08"));

    PreprocessOptions o;
    o.inputs = {dir_ / "sphere.obj"};
    o.output = dir_ / "none.nave";
    o.brick_triangles = 1000;
    auto without = RunPreprocess(o);
    ASSERT_TRUE(without.ok()) << without.status().ToString();
    EXPECT_TRUE(without->level_triangles.empty());
    EXPECT_THAT(FormatSummary(*without), HasSubstr("levels:      none"));
    store = store::Store::Open(dir_ / "none.nave");
    ASSERT_TRUE(store.ok());
    for (const store::BrickInfo& b : (*store)->bricks()) EXPECT_TRUE(b.levels.empty());
    EXPECT_THAT((*store)->header().provenance.options, HasSubstr("level-errors=none"));
    EXPECT_LT(without->output_bytes, with.output_bytes);

    o.encode.levels.relative_errors = {0.2, 0.1};  // not increasing
    EXPECT_EQ(RunPreprocess(o).status().code(), StatusCode::kInvalidArgument);
    std::filesystem::remove(dir_ / "levels.nave");
    std::filesystem::remove(dir_ / "none.nave");
}

TEST_F(PartitionedSphere, ManyBricksHoldExactlyTheInputTriangles) {
    auto stats = Run(dir_ / "a.nave", 0, 2);
    EXPECT_GE(stats.bricks, 16u);
    auto store = store::Store::Open(dir_ / "a.nave");
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    const auto& grid = (*store)->header().grid;
    auto input = testing::ReadModel(dir_ / "sphere.obj");
    std::set<QTri, QTriLess> expected;
    for (const auto& t : input)
        expected.insert(
            Canonical({grid.Quantize(t.p[0]), grid.Quantize(t.p[1]), grid.Quantize(t.p[2])}));
    uint64_t refs = 0;
    auto got = StoreTriangles(**store, &refs);
    EXPECT_EQ(got.size(), expected.size());
    EXPECT_TRUE(got == expected) << "the bricks' triangles, as a set, differ from the input's";
    EXPECT_EQ(refs, stats.stored_triangles);
    EXPECT_EQ(refs - input.size(), stats.duplicated_triangles);
    EXPECT_EQ((*store)->header().source_triangle_count, input.size());
    // Quantization bound: every decoded position is within step * sqrt(3) / 2 of an input vertex's.
    EXPECT_NEAR(stats.max_error, grid.step * std::sqrt(3.0) / 2, 1e-12);
    // No temporary files left.
    for (const auto& e : std::filesystem::directory_iterator(dir_)) {
        EXPECT_THAT(e.path().filename().string(), ::testing::Not(HasSubstr("tmp"))) << e.path();
    }
}

TEST_F(PartitionedSphere, SmallBudgetAndOneThreadGiveTheSameTriangles) {
    auto a = Run(dir_ / "big.nave", 0, 2);
    auto b = Run(dir_ / "small.nave", 64ull << 20, 1);
    auto sa = store::Store::Open(dir_ / "big.nave");
    auto sb = store::Store::Open(dir_ / "small.nave");
    ASSERT_TRUE(sa.ok() && sb.ok());
    uint64_t ra = 0, rb = 0;
    EXPECT_TRUE(StoreTriangles(**sa, &ra) == StoreTriangles(**sb, &rb));
    EXPECT_EQ(a.source_triangles, b.source_triangles);
}

// Rays from inside the closed sphere, walked brick by brick front to back as the renderer does:
// each brick intersected only within its own cell's [t_enter, t_exit]. A crack between bricks lets
// a ray escape.
TEST_F(PartitionedSphere, NoRayEscapesBetweenBricks) {
    Run(dir_ / "w.nave", 0, 2);
    auto store = store::Store::Open(dir_ / "w.nave");
    ASSERT_TRUE(store.ok());
    const store::Store& s = **store;
    ASSERT_GE(s.bricks().size(), 16u);
    RTCDevice device = rtcNewDevice(nullptr);
    ASSERT_NE(device, nullptr);
    std::vector<RTCScene> scenes;
    for (uint32_t b = 0; b < s.bricks().size(); ++b) {
        auto mesh = s.ReadBrick(b);
        ASSERT_TRUE(mesh.ok());
        RTCScene scene = rtcNewScene(device);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                               mesh->VertexCount()));
        for (size_t i = 0; i < mesh->VertexCount(); ++i) {
            vb[3 * i] = mesh->positions[i].x;
            vb[3 * i + 1] = mesh->positions[i].y;
            vb[3 * i + 2] = mesh->positions[i].z;
        }
        auto* ib = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(unsigned), mesh->TriangleCount()));
        std::copy(mesh->indices.begin(), mesh->indices.end(), ib);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(scene);
        scenes.push_back(scene);
    }
    std::mt19937 rng(12345);
    std::normal_distribution<float> n(0, 1);
    std::uniform_real_distribution<float> u(-1, 1);
    const Vec3f centre(3, -2, 1);
    int escaped = 0;
    const int kRays = 20000;
    for (int i = 0; i < kRays; ++i) {
        Vec3f d = Normalize(Vec3f(n(rng), n(rng), n(rng)));
        Vec3f o = centre + Vec3f(u(rng), u(rng), u(rng)) * 1.0f;  // anywhere well inside (radius 2)
        bool hit = false;
        s.tree().Traverse(o, d, 0.f, 1e30f, [&](uint32_t brick, float t0, float t1) {
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            RTCRayHit rh{};
            rh.ray.org_x = o.x;
            rh.ray.org_y = o.y;
            rh.ray.org_z = o.z;
            rh.ray.dir_x = d.x;
            rh.ray.dir_y = d.y;
            rh.ray.dir_z = d.z;
            // A few ulps of slack at the cell faces, as a renderer needs for float cell bounds.
            rh.ray.tnear = std::max(0.f, t0 * (1 - 1e-6f) - 1e-6f);
            rh.ray.tfar = t1 * (1 + 1e-6f) + 1e-6f;
            rh.ray.mask = 0xffffffffu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scenes[brick], &ctx, &rh);
            hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            return !hit;
        });
        if (!hit) ++escaped;
    }
    for (RTCScene sc : scenes) rtcReleaseScene(sc);
    rtcReleaseDevice(device);
    EXPECT_EQ(escaped, 0) << escaped << " of " << kRays << " rays escaped the closed sphere";
}

TEST(PreprocessErrors, BadInputNamesFileAndLineAndLeavesNothing) {
    auto dir = testing::MakeTempDir("bad");
    PreprocessOptions o;
    o.inputs = {testing::Fixture("bad_index.obj")};
    o.output = dir / "bad.nave";
    auto stats = RunPreprocess(o);
    ASSERT_FALSE(stats.ok());
    EXPECT_THAT(stats.status().ToString(), HasSubstr("bad_index.obj:5"));
    EXPECT_TRUE(std::filesystem::is_empty(dir)) << "a failed run must leave no file";
    std::filesystem::remove_all(dir);
}

TEST(PreprocessErrors, BudgetTooSmallSaysWhichOptionToChange) {
    PreprocessOptions o;
    o.inputs = {testing::Fixture("ascii.stl")};
    o.output = std::filesystem::temp_directory_path() / "never.nave";
    o.memory_bytes = 100ull << 20;
    o.brick_triangles = kDefaultBrickTriangles;  // asked for: not lowered behind the user's back
    auto stats = RunPreprocess(o);
    ASSERT_FALSE(stats.ok());
    EXPECT_EQ(stats.status().code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(stats.status().message(), HasSubstr("--memory"));
    EXPECT_THAT(stats.status().message(), HasSubstr("--brick-triangles"));
    EXPECT_FALSE(std::filesystem::exists(o.output));
}

// What a partition made: each leaf's cell, count and a digest of its bin's triangles, in order.
struct LeafDigest {
    Bounds3f cell;
    uint64_t triangles = 0;
    uint64_t hash = 0;
    bool operator==(const LeafDigest& o) const {
        return cell.min == o.cell.min && cell.max == o.cell.max && triangles == o.triangles &&
               hash == o.hash;
    }
};

std::vector<LeafDigest> PartitionAbbey(int threads, int max_fanout) {
    const auto parent = testing::MakeTempDir("split-threads");
    auto temp = TempDir::Create(parent);
    EXPECT_TRUE(temp.ok()) << temp.status().ToString();
    if (!temp.ok()) return {};
    PartitionConfig config;
    config.brick_triangles = 4000;
    config.threads = threads;
    config.max_fanout = max_fanout;
    Partitioner partitioner(config, *temp);
    auto source = MakeAbbeySource(0.25, 1);
    ProgressBar bar("test", 0, "triangles");
    EXPECT_TRUE(partitioner.Bin(*source, bar).ok());
    const Bounds3d& b = partitioner.bounds();
    const Bounds3f root(Vec3f(b.min) - Vec3f(0.01f, 0.01f, 0.01f),
                        Vec3f(b.max) + Vec3f(0.01f, 0.01f, 0.01f));
    Status split = partitioner.Split(root, 0.001, bar);
    EXPECT_TRUE(split.ok()) << split.ToString();
    std::vector<LeafDigest> digests;
    for (const LeafBin& leaf : partitioner.leaves()) {
        LeafDigest d{leaf.cell, leaf.triangles, 0};
        auto reader = BinReader::Open(leaf.file);
        EXPECT_TRUE(reader.ok());
        if (!reader.ok()) continue;
        std::vector<Triangle> batch;
        uint64_t read = 0;
        while (true) {
            batch.clear();
            auto more = (*reader)->Read(batch, 1000);
            EXPECT_TRUE(more.ok());
            if (!more.ok() || !*more) break;
            for (const Triangle& t : batch)
                d.hash = d.hash * 1000003u ^ Checksum64(&t.p, sizeof(t.p)) ^ t.material;
            read += batch.size();
        }
        EXPECT_EQ(read, leaf.triangles);
        digests.push_back(d);
    }
    return digests;
}

// A split pass routes chunks of its bin on every thread but appends them in order: the leaves, and
// the order of the triangles in each, are the same on one thread as on two or three, when the
// root's pass cuts every leaf at once and when bins are cut again (a fan-out of 4 makes several
// levels).
TEST(SplitPass, LeavesDoNotDependOnTheThreadCount) {
    for (int fanout : {4096, 4}) {
        const std::vector<LeafDigest> one = PartitionAbbey(1, fanout);
        ASSERT_GE(one.size(), 16u) << "fan-out " << fanout;
        uint64_t total = 0;
        for (const LeafDigest& d : one) total += d.triangles;
        ASSERT_GT(total, uint64_t(3) << 15) << "more triangles than one chunk of the pass";
        for (int threads : {2, 3}) {
            const std::vector<LeafDigest> many = PartitionAbbey(threads, fanout);
            ASSERT_EQ(many.size(), one.size()) << threads << " threads, fan-out " << fanout;
            for (size_t i = 0; i < one.size(); ++i)
                EXPECT_TRUE(many[i] == one[i])
                    << "leaf " << i << ", " << threads << " threads, fan-out " << fanout;
        }
    }
}

TEST(SplitPass, FanOutFollowsTheBuffersAndTheOpenFileLimit) {
    const uint64_t files = 1 << 20;
    EXPECT_EQ(MaxSplitFanout(size_t(1) << 40, files), 4096) << "at most 4096 leaves a pass";
    EXPECT_EQ(MaxSplitFanout(size_t(64) * 2 * (16 << 10), files), 64) << "two 16 KiB blocks a leaf";
    EXPECT_EQ(MaxSplitFanout(0, files), 2);
    EXPECT_EQ(MaxSplitFanout(size_t(1) << 40, 1024), 896) << "128 files kept for the rest";
    EXPECT_EQ(MaxSplitFanout(size_t(1) << 40, 100), 2);
}

}  // namespace
}  // namespace nave::preprocess
