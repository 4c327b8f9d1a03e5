// The preprocess plan: what a run decides from its options and the machine before any work, and
// each refusal, with the option it names and the numbers it gives. No run: the plan is pure.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "preprocess/partition/brick_builder.h"
#include "preprocess/preprocess_plan.h"

namespace nave::preprocess {
namespace {

using ::testing::HasSubstr;

constexpr uint64_t kMiB = uint64_t(1) << 20;
constexpr uint64_t kGiB = uint64_t(1) << 30;

// A machine with 16 GiB, 8 threads and many files: its defaults are a 4 GiB budget on 8 threads.
MachineResources Machine() {
    MachineResources m;
    m.physical_memory_bytes = 16 * kGiB;
    m.hardware_threads = 8;
    m.open_files = 20000;
    return m;
}

PreprocessOptions Generate(const std::string& output = "out/abbey.nave") {
    PreprocessOptions o;
    o.generate = "abbey:detail=1";
    o.output = output;
    return o;
}

TEST(PreprocessPlan, DefaultsTakeAQuarterOfMemoryEveryThreadAndTheDefaultBrick) {
    auto plan = PlanPreprocess(Generate(), Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_EQ(plan->memory_budget, 4 * kGiB);
    EXPECT_EQ(plan->threads, 8);
    EXPECT_EQ(plan->brick_triangles, kDefaultBrickTriangles);
    EXPECT_FALSE(plan->brick_triangles_fitted);
    EXPECT_EQ(plan->leaf_max_triangles, kDefaultBrickTriangles * 5 / 4);
    EXPECT_EQ(plan->brick_work_bytes, kDefaultBrickTriangles * 5 / 4 * kEncodeBytesPerTriangle);
    EXPECT_EQ(plan->generator_producers, 8) << "a budget of 1 GiB or more: one per thread";
    EXPECT_EQ(plan->partition.brick_triangles, kDefaultBrickTriangles);
    EXPECT_EQ(plan->partition.threads, 8);
    EXPECT_EQ(plan->partition.split_buffer_bytes, 4 * kGiB / 16);
    EXPECT_EQ(plan->partition.block_bytes, size_t(256) << 10) << "at most 256 KiB";
    EXPECT_EQ(plan->partition.max_fanout, 4096) << "8192 by the buffers, at most 4096";
    EXPECT_EQ(plan->temp_parent, std::filesystem::path("out"));
}

TEST(PreprocessPlan, OptionsOverrideTheMachine) {
    PreprocessOptions o = Generate("abbey.nave");
    o.memory_bytes = 900 * kMiB;
    o.threads = 3;
    o.brick_triangles = 20000;
    o.temp_dir = "/scratch";
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_EQ(plan->memory_budget, 900 * kMiB);
    EXPECT_EQ(plan->threads, 3);
    EXPECT_EQ(plan->brick_triangles, 20000u);
    EXPECT_FALSE(plan->brick_triangles_fitted) << "asked for, not fitted";
    EXPECT_EQ(plan->generator_producers, 1) << "under 1 GiB: one producer";
    EXPECT_EQ(plan->temp_parent, std::filesystem::path("/scratch"));
    o.temp_dir.clear();
    plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok());
    EXPECT_EQ(plan->temp_parent, std::filesystem::path(".")) << "an output without a directory";
}

// Without --brick-triangles, a budget too small for the default brick gets the largest brick whose
// work it holds: 48 MiB fixed + 5 000 x 5/4 x 600 bytes gives 5 000 triangles.
TEST(PreprocessPlan, SmallBudgetWithoutBrickSizeFitsTheBrick) {
    PreprocessOptions o = Generate();
    o.memory_bytes = kFixedBytes + 5000 * 5 / 4 * kEncodeBytesPerTriangle;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_EQ(plan->brick_triangles, 5000u);
    EXPECT_TRUE(plan->brick_triangles_fitted);
    EXPECT_LE(kFixedBytes + plan->brick_work_bytes, plan->memory_budget);
    EXPECT_EQ(plan->partition.split_buffer_bytes, plan->memory_budget / 16);
    EXPECT_EQ(plan->partition.block_bytes, plan->memory_budget / 16 / 128)
        << "two blocks for each of 64 bins in the split's share";
}

TEST(PreprocessPlan, FanOutFollowsTheOpenFileLimit) {
    MachineResources m = Machine();
    m.open_files = 200;
    auto plan = PlanPreprocess(Generate(), m);
    ASSERT_TRUE(plan.ok());
    EXPECT_EQ(plan->partition.max_fanout, 72) << "200 files less 128 for the rest";
}

TEST(PreprocessPlan, RefusesNeitherOrBothInputs) {
    PreprocessOptions neither;
    neither.output = "a.nave";
    auto plan = PlanPreprocess(neither, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(plan.status().message(),
              "give either model files or --generate abbey[:detail=D], not neither");
    PreprocessOptions both = Generate();
    both.inputs = {"model.obj"};
    plan = PlanPreprocess(both, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_THAT(plan.status().message(), HasSubstr("not both"));
    // A .vdb is a medium, not a model: alone it is no input, beside the generator it is welcome.
    PreprocessOptions medium_only;
    medium_only.output = "a.nave";
    medium_only.inputs = {"dust.vdb"};
    plan = PlanPreprocess(medium_only, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_THAT(plan.status().message(), HasSubstr("not neither (a .vdb file is a medium"));
    PreprocessOptions generated_with_medium = Generate();
    generated_with_medium.inputs = {"dust.VDB"};
    plan = PlanPreprocess(generated_with_medium, Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    EXPECT_EQ(plan->medium, "dust.VDB");
    EXPECT_TRUE(plan->models.empty());
}

TEST(PreprocessPlan, RefusesTwoMediaNamingBoth) {
    PreprocessOptions o;
    o.output = "a.nave";
    o.inputs = {"a.vdb", "model.obj", "b.vdb"};
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(plan.status().message(), HasSubstr("two media given, a.vdb and b.vdb"));
}

TEST(PreprocessPlan, RefusesNoOutput) {
    auto plan = PlanPreprocess(Generate(""), Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(plan.status().message(), "no output file given (-o MODEL.nave)");
}

TEST(PreprocessPlan, RefusesBricksUnderTheMinimum) {
    PreprocessOptions o = Generate();
    o.brick_triangles = kMinBrickTriangles - 1;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(plan.status().message(), "--brick-triangles 999: expected at least 1000");
}

TEST(PreprocessPlan, RefusesANegativePrecision) {
    PreprocessOptions o = Generate();
    o.precision = -0.5;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(plan.status().message(), "--precision -0.5: must be positive");
}

// The example of docs/preprocess.md: a 1 M target under --memory 100M.
TEST(PreprocessPlan, RefusesABudgetThatCannotHoldOneBrickAndSaysWhatWould) {
    PreprocessOptions o = Generate();
    o.memory_bytes = 100 * kMiB;
    o.brick_triangles = 1'000'000;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kResourceExhausted);
    EXPECT_EQ(plan.status().message(),
              "--memory 100.0 MiB cannot hold the work for one brick: 1250000 triangles x 600 "
              "bytes = 715.3 MiB plus 48.0 MiB fixed; raise --memory to at least 763.3 MiB or "
              "lower --brick-triangles to at most 72700");
}

TEST(PreprocessPlan, RefusesABudgetUnderTheSmallestBrickEvenWithoutBrickSize) {
    PreprocessOptions o = Generate();
    o.memory_bytes = kFixedBytes;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_FALSE(plan.ok());
    EXPECT_EQ(plan.status().code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(plan.status().message(), HasSubstr("1250 triangles"));
}

TEST(PreprocessPlan, TextureConversionNeedsItsShareOfTheBudget) {
    PreprocessOptions o = Generate();
    o.brick_triangles = kMinBrickTriangles;
    o.memory_bytes = kFixedBytes + 1250 * kEncodeBytesPerTriangle + kTextureConversionBytes;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    auto reserve = PlanTextureReserve(*plan);
    ASSERT_TRUE(reserve.ok()) << reserve.status().ToString();
    EXPECT_EQ(*reserve, kTextureConversionBytes);

    o.memory_bytes -= 1;
    plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok());
    reserve = PlanTextureReserve(*plan);
    ASSERT_FALSE(reserve.ok());
    EXPECT_EQ(reserve.status().code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(reserve.status().message(),
                HasSubstr("cannot hold texture conversion (160.0 MiB for OpenImageIO)"));
    EXPECT_THAT(reserve.status().message(), HasSubstr("--no-textures"));
}

TEST(PreprocessPlan, GridStepIsTheDiagonalOver2To20UnlessGiven) {
    const Bounds3d bounds(Vec3d(0, 0, 0), Vec3d(3, 4, 0));
    auto grid = PlanGrid(0, bounds);
    ASSERT_TRUE(grid.ok()) << grid.status().ToString();
    EXPECT_DOUBLE_EQ(grid->grid.step, 5.0 / double(1 << 20));
    EXPECT_DOUBLE_EQ(grid->max_error, grid->grid.step * std::sqrt(3.0) / 2);
    EXPECT_EQ(grid->grid.origin.x, 0.0);
    EXPECT_LT(grid->root.min.x, 0.f) << "the root cell is grown by a step";
    EXPECT_GT(grid->root.max.y, 4.f);

    grid = PlanGrid(0.25, bounds);
    ASSERT_TRUE(grid.ok());
    EXPECT_EQ(grid->grid.step, 0.25);
}

TEST(PreprocessPlan, RefusesAPrecisionFinerThan2To29StepsAcross) {
    const Bounds3d bounds(Vec3d(0, 0, 0), Vec3d(1000, 1, 1));
    auto grid = PlanGrid(1e-9, bounds);
    ASSERT_FALSE(grid.ok());
    EXPECT_EQ(grid.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(grid.status().message(), HasSubstr("--precision 1e-09: the model is 1000 units"));
    EXPECT_THAT(grid.status().message(), HasSubstr("at most 2^29 fit"));
}

std::vector<LeafBin> Leaves(std::initializer_list<uint64_t> triangles) {
    std::vector<LeafBin> leaves;
    for (uint64_t t : triangles) {
        LeafBin leaf;
        leaf.triangles = t;
        leaves.push_back(leaf);
    }
    return leaves;
}

// Each encoding thread keeps buffers for the largest leaf: the budget left after the fixed part
// and the textures sets how many run at once.
TEST(PreprocessPlan, EncodeThreadsAreAsManyAsTheBudgetHolds) {
    PreprocessOptions o = Generate();
    o.threads = 8;
    o.brick_triangles = 10000;
    o.memory_bytes = kFixedBytes + 3 * 12500 * kEncodeBytesPerTriangle + 100;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    auto encode = PlanEncode(*plan, 0, Leaves({12500, 9000, 400}));
    ASSERT_TRUE(encode.ok()) << encode.status().ToString();
    EXPECT_EQ(encode->largest_leaf, 12500u);
    EXPECT_EQ(encode->threads, 3);
    EXPECT_EQ(encode->budget, 3 * 12500 * kEncodeBytesPerTriangle + 100);

    encode = PlanEncode(*plan, 0, Leaves({100, 200}));
    ASSERT_TRUE(encode.ok());
    EXPECT_EQ(encode->threads, 8) << "at most the plan's threads";
}

TEST(PreprocessPlan, RefusesALeafTooBigToEncode) {
    PreprocessOptions o = Generate();
    o.brick_triangles = 10000;
    o.memory_bytes = kFixedBytes + 12500 * kEncodeBytesPerTriangle;
    auto plan = PlanPreprocess(o, Machine());
    ASSERT_TRUE(plan.ok()) << plan.status().ToString();
    auto encode = PlanEncode(*plan, 0, Leaves({5000, 40000}));
    ASSERT_FALSE(encode.ok());
    EXPECT_EQ(encode.status().code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(encode.status().message(), HasSubstr("a brick of 40000 triangles"));
    EXPECT_THAT(encode.status().message(), HasSubstr("raise --memory to at least 70.9 MiB"));
}

}  // namespace
}  // namespace nave::preprocess
