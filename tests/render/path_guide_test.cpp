// Path guiding (render.path_guiding): the guide's histograms as distributions (their samples follow
// their pdf, the pdf integrates to one, credits in any order give the same distribution), and
// guided path tracing in a room lit by the sun and sky through a window in its roof: the same image
// in expectation as BSDF sampling alone, and the same image whatever the bricks and threads.

#include "src/render/transport/path_guide.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <barrier>
#include <cmath>
#include <functional>
#include <memory>
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "render_test_util.h"
#include "src/core/sampling.h"
#include "src/render/scene/materials/bxdf.h"
#include "src/render/stream/ray.h"

namespace nave::render {
namespace {

const Bounds3f kBox(Vec3f(0, 0, 0), Vec3f(4, 4, 4));
const int kSide = PathGuide::SideOf(Vec3f(0, 0, 1));  // the unit tests' surfaces face up
// The pass of the credits and queries on guides whose every Update closes a round
// (GuideRounds::kEveryUpdate, the default), which ignore it.
constexpr uint32_t kAnyPass = 0;

Vec3f UniformDirection(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.f, 1.f);
    // One draw after the other: the arguments of one call are evaluated in an order each compiler
    // picks, and the tests' sums must not depend on it.
    const float u0 = u(rng);
    const float u1 = u(rng);
    return SampleUniformSphere(Point2f(u0, u1));
}

/// A guide whose cell at (1, 1, 1) learned light mostly from +x and some from -z.
std::unique_ptr<PathGuide> LearnedGuide() {
    auto guide = std::make_unique<PathGuide>(kBox, 4, 16, 1.0);
    const Vec3f p(1, 1, 1);
    // Cells get their histograms at an update, and learn from the credits after it.
    for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i < 300; ++i)
            guide->Credit(guide->CreditKey(p, kSide, Normalize(Vec3f(1, 0.1f, 0.05f))), 2.0,
                          kAnyPass);
        for (int i = 0; i < 100; ++i)
            guide->Credit(guide->CreditKey(p, kSide, Vec3f(0, 0, -1)), 1.0, kAnyPass);
        guide->Update();
    }
    return guide;
}

TEST(PathGuide, SamplesFollowThePdfThatIntegratesToOne) {
    const std::unique_ptr<PathGuide> learned = LearnedGuide();
    const PathGuide& guide = *learned;
    const Vec3f p(1.2f, 1.3f, 1.4f);  // same cell
    ASSERT_TRUE(guide.Guides(p, kSide, kAnyPass));
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    // The bins have equal solid angles: uniform directions fall in them equally (chi² with 255
    // degrees of freedom, far tail).
    std::vector<double> uniform(PathGuide::kBins, 0);
    constexpr int kUniform = 256000;
    for (int i = 0; i < kUniform; ++i)
        uniform[size_t(PathGuide::BinOf(UniformDirection(rng)))] += 1;
    double uniform_chi2 = 0;
    for (double c : uniform) uniform_chi2 += (c - 1000) * (c - 1000) / 1000;
    EXPECT_LT(uniform_chi2, 255 + 5 * std::sqrt(2.0 * 255));
    // So the pdf over the sphere, constant in each bin, integrates to one.
    double integral = 0;
    for (int b = 0; b < PathGuide::kBins; ++b) {
        const int z_bin = b / PathGuide::kPhiBins;
        const float z = -1 + 2 * (float(z_bin) + 0.5f) / PathGuide::kZBins;
        const float phi = 2 * kPi * (float(b % PathGuide::kPhiBins) + 0.5f) / PathGuide::kPhiBins;
        const Vec3f w(std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi),
                      z);
        ASSERT_EQ(PathGuide::BinOf(w), b);
        integral += guide.Pdf(p, kSide, w, 0) * 4 * kPi / PathGuide::kBins;
    }
    EXPECT_NEAR(integral, 1.0, 1e-5);
    // Sampled directions land in the bins in proportion to pdf x the bin's solid angle, and each
    // sample's pdf is Pdf's.
    std::vector<double> counts(PathGuide::kBins, 0), expected(PathGuide::kBins, 0);
    constexpr int kSamples = 100000;
    for (int i = 0; i < kSamples; ++i) {
        std::optional<GuideSample> s = guide.Sample(p, kSide, u(rng), u(rng), u(rng), 0);
        ASSERT_TRUE(s);
        ASSERT_NEAR(Length(s->wi), 1.f, 1e-5f);
        ASSERT_FLOAT_EQ(s->pdf, guide.Pdf(p, kSide, s->wi, 0));
        counts[size_t(PathGuide::BinOf(s->wi))] += 1;
        expected[size_t(PathGuide::BinOf(s->wi))] = s->pdf * 4 * kPi / PathGuide::kBins * kSamples;
    }
    double chi2 = 0;
    int dof = 0;
    for (int b = 0; b < PathGuide::kBins; ++b) {
        if (expected[size_t(b)] < 5) continue;
        chi2 += (counts[size_t(b)] - expected[size_t(b)]) *
                (counts[size_t(b)] - expected[size_t(b)]) / expected[size_t(b)];
        ++dof;
    }
    // The guide learned +x three times as strongly per credit count (600 against 100): its bin
    // holds most of the 90 % that is learned.
    EXPECT_GT(dof, 10);
    EXPECT_LT(chi2, dof + 5 * std::sqrt(2.0 * dof)) << "dof " << dof;
    const int bright = PathGuide::BinOf(Normalize(Vec3f(1, 0.1f, 0.05f)));
    EXPECT_NEAR(counts[size_t(bright)] / kSamples, 0.9 * 600 / 700 + 0.1 / PathGuide::kBins, 0.01);
}

TEST(PathGuide, SidesAreTheNormalsLargestAxisAndItsSign) {
    EXPECT_EQ(PathGuide::SideOf(Vec3f(0.9f, 0.3f, -0.3f)), 0);
    EXPECT_EQ(PathGuide::SideOf(Vec3f(-0.9f, 0.3f, -0.3f)), 1);
    EXPECT_EQ(PathGuide::SideOf(Vec3f(0.2f, 0.7f, 0.6f)), 2);
    EXPECT_EQ(PathGuide::SideOf(Vec3f(0.2f, -0.7f, 0.6f)), 3);
    EXPECT_EQ(PathGuide::SideOf(Vec3f(0, 0, 1)), 4);
    EXPECT_EQ(PathGuide::SideOf(Vec3f(0.1f, 0.1f, -0.99f)), 5);
}

TEST(PathGuide, TheOrderOfCreditsDoesNotChangeTheDistribution) {
    std::mt19937 rng(3);
    std::vector<std::pair<Vec3f, double>> credits;
    credits.reserve(5000);
    for (int i = 0; i < 5000; ++i)
        credits.push_back(
            {UniformDirection(rng), std::exp(std::uniform_real_distribution<double>(-8, 3)(rng))});
    PathGuide a(kBox, 4, 16, 1.0), b(kBox, 4, 16, 1.0);
    const Vec3f p(3.5f, 0.5f, 2.5f);
    for (int pass = 0; pass < 2; ++pass) {
        for (const auto& [w, v] : credits) a.Credit(a.CreditKey(p, kSide, w), v, kAnyPass);
        std::shuffle(credits.begin(), credits.end(), rng);
        for (const auto& [w, v] : credits) b.Credit(b.CreditKey(p, kSide, w), v, kAnyPass);
        a.Update();
        b.Update();
    }
    ASSERT_TRUE(a.Guides(p, kSide, kAnyPass));
    for (int i = 0; i < 1000; ++i) {
        const Vec3f w = UniformDirection(rng);
        ASSERT_EQ(a.Pdf(p, kSide, w, 0), b.Pdf(p, kSide, w, 0));  // bit for bit
    }
}

// Two processes of a distributed render, each crediting half the paths, share their credits
// before each update: both end with the guide one process crediting every path has, bit for bit,
// over several updates (each shares only what was credited since the last).
// The sum over two "processes" of a distributed render, each a thread: each offers its values
// and waits for the other's.
class TwoProcessSum {
  public:
    std::function<Status(std::span<uint64_t>)> Of(int me) {
        return [this, me](std::span<uint64_t> values) {
            offered_[me].assign(values.begin(), values.end());
            meet_.arrive_and_wait();
            const std::vector<uint64_t>& other = offered_[1 - me];
            if (other.size() != values.size()) return InternalError("sizes differ");
            for (size_t i = 0; i < values.size(); ++i) values[i] += other[i];
            meet_.arrive_and_wait();  // both have read before either offers again
            return Status::Ok();
        };
    }
    /// Both guides share their credits, each on its own thread.
    void Share(PathGuide& a, PathGuide& b) {
        Status shared[2];
        std::thread other([&] { shared[1] = b.ShareCredits(Of(1)); });
        shared[0] = a.ShareCredits(Of(0));
        other.join();
        ASSERT_TRUE(shared[0].ok() && shared[1].ok())
            << shared[0].ToString() << shared[1].ToString();
    }

  private:
    std::barrier<> meet_{2};
    std::vector<uint64_t> offered_[2];
};

// Updates the guide of one process and those of two processes that shared their credits, and
// expects the two to hold the one's state, bit for bit.
void ExpectUpdatesAlike(PathGuide& one, PathGuide& a, PathGuide& b) {
    one.Update();
    a.Update();
    b.Update();
    ByteWriter state_one, state_a, state_b;
    one.SaveState(&state_one);
    a.SaveState(&state_a);
    b.SaveState(&state_b);
    const std::string expected = state_one.Take();
    EXPECT_EQ(state_a.Take(), expected);
    EXPECT_EQ(state_b.Take(), expected);
}

TEST(PathGuide, SharedCreditsGiveEveryProcessTheGuideOfOne) {
    std::mt19937 rng(11);
    PathGuide one(kBox, 4, 16, 1.0), a(kBox, 4, 16, 1.0), b(kBox, 4, 16, 1.0);
    TwoProcessSum sum;
    const Vec3f points[2] = {Vec3f(3.5f, 0.5f, 2.5f), Vec3f(0.5f, 3.5f, 1.0f)};
    for (int pass = 0; pass < 3; ++pass) {
        for (int i = 0; i < 4000; ++i) {
            const Vec3f p = points[i % 2];
            const Vec3f w = UniformDirection(rng);
            const double v = std::exp(std::uniform_real_distribution<double>(-6, 2)(rng));
            one.Credit(one.CreditKey(p, kSide, w), v, kAnyPass);
            PathGuide& half = (i / 7) % 2 == 0 ? a : b;
            half.Credit(half.CreditKey(p, kSide, w), v, kAnyPass);
        }
        sum.Share(a, b);
        SCOPED_TRACE(::testing::Message() << "pass " << pass);
        ExpectUpdatesAlike(one, a, b);
    }
    EXPECT_TRUE(one.Guides(points[0], kSide, kAnyPass));
}

// A checkpoint of a distributed render: the processes share their credits mid-pass, one saves the
// guide, and the processes resumed from it share only what they credit afterwards, ending with the
// guide of one process that credited every path, bit for bit.
TEST(PathGuide, ProcessesResumedFromASharedCheckpointShareOnlyNewCredits) {
    std::mt19937 rng(5);
    PathGuide one(kBox, 4, 16, 1.0), a(kBox, 4, 16, 1.0), b(kBox, 4, 16, 1.0);
    const Vec3f p(3.5f, 0.5f, 2.5f);
    auto credit = [&](int n, PathGuide& x, PathGuide& y) {
        for (int i = 0; i < n; ++i) {
            const Vec3f w = UniformDirection(rng);
            const double v = std::exp(std::uniform_real_distribution<double>(-6, 2)(rng));
            one.Credit(one.CreditKey(p, kSide, w), v, kAnyPass);
            PathGuide& half = i % 3 == 0 ? x : y;
            half.Credit(half.CreditKey(p, kSide, w), v, kAnyPass);
        }
    };
    TwoProcessSum before;
    credit(3000, a, b);
    before.Share(a, b);
    one.Update();
    a.Update();
    b.Update();
    credit(1500, a, b);
    before.Share(a, b);  // the checkpoint, mid-pass
    ByteWriter checkpoint;
    a.SaveState(&checkpoint);
    const std::string bytes = checkpoint.Take();
    PathGuide c(kBox, 4, 16, 1.0), d(kBox, 4, 16, 1.0);
    for (PathGuide* resumed : {&c, &d}) {
        ByteReader in(bytes, "checkpoint");
        ASSERT_TRUE(resumed->LoadState(&in).ok());
    }
    credit(1500, c, d);
    TwoProcessSum after;
    after.Share(c, d);
    ExpectUpdatesAlike(one, c, d);
    EXPECT_TRUE(one.Guides(p, kSide, kAnyPass));
}

// Path mode's rounds (GuideRounds::kDoublingPasses): a render under a memory budget begins round
// r while round r - 1's last paths are still crediting, and Updates the guide between two of their
// credits. The guide must end where a render that drained every round first ends, bit for bit, and
// each pass must sample what the round two before it closed.
TEST(PathGuide, RoundsEndTheSameWhetherTheirLastCreditsComeBeforeOrAfterAnUpdate) {
    std::mt19937 rng(17);
    const Vec3f points[2] = {Vec3f(0.5f, 0.5f, 0.5f), Vec3f(3.2f, 1.5f, 2.5f)};
    struct Credit {
        uint32_t pass;
        Vec3f p, w;
        double value;
    };
    // Rounds 0-1 | 2-3 | 4-7 | 8-15, 300 credits a pass.
    std::vector<Credit> rounds[4];
    for (uint32_t pass = 0; pass < FirstPassOfRound(4); ++pass) {
        for (int i = 0; i < 300; ++i) {
            const Vec3f w = UniformDirection(rng);
            const double v = std::exp(std::uniform_real_distribution<double>(-4, 2)(rng));
            rounds[RoundOfPass(pass)].push_back({pass, points[i % 2], w, v});
        }
    }
    auto credit = [](PathGuide& g, const std::vector<Credit>& c, size_t from, size_t to) {
        for (size_t i = from; i < to; ++i)
            g.Credit(g.CreditKey(c[i].p, kSide, c[i].w), c[i].value, c[i].pass);
    };
    auto make = [] { return PathGuide(kBox, 4, 2048, 1.0, GuideRounds::kDoublingPasses); };
    // Drained: every round ends before the next begins; round r + 2 begins with the Update of r.
    PathGuide drained = make();
    credit(drained, rounds[0], 0, rounds[0].size());
    credit(drained, rounds[1], 0, rounds[1].size());
    const uint32_t round_1 = FirstPassOfRound(1), round_2 = FirstPassOfRound(2);
    EXPECT_FALSE(drained.Guides(points[0], kSide, round_1)) << "round 1 samples nothing";
    drained.Update();  // closes round 0: round 2 samples it
    EXPECT_TRUE(drained.Guides(points[0], kSide, round_2)) << "the coarse cells learned";
    EXPECT_FALSE(drained.Guides(points[0], kSide, round_1));
    const Vec3f w = Normalize(Vec3f(0.3f, -0.2f, 0.9f));
    const float round_0_pdf = drained.Pdf(points[0], kSide, w, round_2);
    credit(drained, rounds[2], 0, rounds[2].size());
    drained.Update();  // closes round 1: round 3 samples it
    credit(drained, rounds[3], 0, rounds[3].size());
    drained.Update();  // closes round 2
    // Overlapped: each Update comes while the round after the closed one is half done.
    PathGuide overlapped = make();
    credit(overlapped, rounds[0], 0, rounds[0].size());
    credit(overlapped, rounds[1], 0, 100);
    overlapped.Update();
    EXPECT_EQ(overlapped.Pdf(points[0], kSide, w, round_2), round_0_pdf)
        << "round 1's credits before the Update are not round 0's";
    credit(overlapped, rounds[1], 100, rounds[1].size());
    credit(overlapped, rounds[2], 0, 700);
    overlapped.Update();
    credit(overlapped, rounds[2], 700, rounds[2].size());
    credit(overlapped, rounds[3], 0, 1000);
    overlapped.Update();
    credit(overlapped, rounds[3], 1000, rounds[3].size());
    EXPECT_EQ(overlapped.rounds_closed(), 3u);
    ByteWriter a, b;
    drained.SaveState(&a);
    overlapped.SaveState(&b);
    EXPECT_EQ(a.Take(), b.Take());
    for (uint32_t round : {2u, 3u, 4u}) {
        const uint32_t pass = FirstPassOfRound(round);
        EXPECT_EQ(overlapped.Pdf(points[1], kSide, w, pass), drained.Pdf(points[1], kSide, w, pass))
            << "pass " << pass;
    }
}

TEST(PathGuide, GuidesOnlyCellsThatLearnedEnoughWithinTheCap) {
    PathGuide guide(kBox, 4, 1, 1.0);  // one cell with a histogram at most
    const Vec3f first(0.5f, 0.5f, 0.5f), second(3.5f, 3.5f, 3.5f), outside(5, 5, 5);
    const Vec3f up(0, 0, 1);
    EXPECT_EQ(guide.CreditKey(outside, kSide, up), PathGuide::kNoCredit);
    auto credit = [&](const Vec3f& p, int n) {
        for (int i = 0; i < n; ++i) guide.Credit(guide.CreditKey(p, kSide, up), 1.0, kAnyPass);
    };
    // Counted, not learned: the cell with most credits gets the one histogram at the update.
    credit(first, 20);
    credit(second, 19);
    guide.Update();
    EXPECT_EQ(guide.cells_used(), 1u);
    EXPECT_FALSE(guide.Guides(first, kSide, kAnyPass)) << "no credits since its histogram came";
    credit(first, 63);
    credit(second, 100);
    guide.Update();
    EXPECT_FALSE(guide.Guides(first, kSide, kAnyPass)) << "63 credits are fewer than Update's 64";
    credit(first, 1);
    guide.Update();
    EXPECT_TRUE(guide.Guides(first, kSide, kAnyPass));
    EXPECT_FALSE(guide.Guides(first, PathGuide::SideOf(Vec3f(0.1f, -0.9f, 0.3f)), kAnyPass))
        << "a wall in the same cell keeps its own histogram";
    EXPECT_FALSE(guide.Guides(second, kSide, kAnyPass)) << "beyond the cap";
    EXPECT_FALSE(guide.Guides(outside, kSide, kAnyPass));
    EXPECT_EQ(guide.cells_used(), 1u);
    EXPECT_EQ(guide.cells_guiding(), 1u);
    EXPECT_EQ(guide.Pdf(second, kSide, up, 0), 0.f);
    EXPECT_FALSE(guide.Sample(second, kSide, 0.5f, 0.5f, 0.5f, 0));
}

TEST(GuidedBsdf, MixtureSamplesFollowTheMixturePdf) {
    const std::unique_ptr<PathGuide> learned = LearnedGuide();
    const PathGuide& guide = *learned;
    const Vec3f p(1, 1, 1);
    DiffuseBxdf diffuse(SampledSpectrum(0.8f));
    const Bsdf bsdf(Vec3f(0, 0, 1), Vec3f(1, 0, 0), Bxdf(diffuse));
    const GuidedBsdf continuation(bsdf, &guide, p, kSide, 0);
    ASSERT_TRUE(continuation.guided());
    const SampledWavelengths lambda = SampledWavelengths::SampleVisible(0.3f);
    const Vec3f wo = Normalize(Vec3f(0.3f, -0.2f, 1));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    // Over the sphere the mixture pdf integrates to one (the guide's part reaches below the
    // surface, where the diffuse BSDF reflects nothing).
    double below = 0, integral = 0, squares = 0;
    constexpr int kN = 2000000;
    for (int i = 0; i < kN; ++i) {
        const Vec3f w = UniformDirection(rng);
        const double x = continuation.Pdf(wo, w, lambda) * 4 * kPi;
        integral += x;
        squares += x * x;
        if (w.z < 0) below += guide.Pdf(p, kSide, w, 0) * 4 * kPi;
    }
    // Within 4 standard errors of the estimate (the guide's peaked bins make it 0.45 % at this
    // count), which is itself small enough that a pdf off by a few percent fails.
    const double mean = integral / kN;
    const double standard_error = std::sqrt((squares / kN - mean * mean) / kN);
    EXPECT_LT(standard_error, 0.006);
    EXPECT_NEAR(mean, 1.0, 4 * standard_error);
    // Samples: pdf as Pdf says, f as the BSDF's, and a guide sample below the surface ends the
    // path.
    int ended = 0;
    for (int i = 0; i < 20000; ++i) {
        std::optional<BsdfSample> s = continuation.Sample(
            wo, u(rng), u(rng), Point2f(u(rng), u(rng)), {u(rng), u(rng), u(rng)}, lambda);
        if (!s) {
            ++ended;
            continue;
        }
        ASSERT_NEAR(s->pdf, continuation.Pdf(wo, s->wi, lambda), 1e-4f * s->pdf);
        ASSERT_GT(s->wi.z, 0);
        ASSERT_EQ(s->f[0], bsdf.Eval(wo, s->wi, lambda)[0]);
    }
    EXPECT_NEAR(ended / 20000.0, GuidedBsdf::kGuideShare * below / kN, 0.015);
}

// The room of render_test_util.h with the sun through the hole in its roof: a sunlit patch on the
// floor lights the walls, which the camera sees.
const std::vector<std::string> kMaterials = {"floor", "wall", "window"};
constexpr const char* kRoom = R"(
[camera]
position = [1.6, -1.7, 2.2]
look_at = [-2.0, 1.0, 1.2]
up = [0, 0, 1]
fov_deg = 60
resolution = [24, 24]
[sun]
direction = [0.25, 0.2, 1.0]
[sky]
radiance = 0.2
[materials.floor]
reflectance = 0.7
[materials.wall]
reflectance = 0.6
[materials.window]
type = "thin_dielectric"
eta = 1.5
[render]
spp = 512
max_depth = 3
)";

testing::SeedPair RenderRoom(bool guiding) {
    return testing::RenderSeedPair(
        testing::RoomWithRoofWindow(), kMaterials,
        std::string(kRoom) + "path_guiding = " + (guiding ? "true" : "false"), 2);
}

// Guiding changes how paths are sampled, not what they estimate. (How much noise it saves is
// measured on the abbey, docs/render.md; in this small room it learns late and saves little.)
TEST(PathGuiding, SameImageInExpectation) {
    const testing::SeedPair plain = RenderRoom(false), guided = RenderRoom(true);
    ASSERT_GT(plain.mean, 0);
    EXPECT_EQ(plain.stats.guide_cells_guiding, 0u);
    EXPECT_GT(guided.stats.guide_cells_guiding, 20u)
        << "the guide learned too little to test anything";
    const double tolerance =
        4 * std::hypot(plain.noise, guided.noise) / std::sqrt(2.0 * double(plain.pixels));
    EXPECT_NEAR(guided.mean, plain.mean, tolerance)
        << "plain noise " << plain.noise << ", guided " << guided.noise;
}

TEST(PathGuiding, TheImageDoesNotDependOnBricksOrThreads) {
    const std::string config = std::string(kRoom) + "path_guiding = true\n";
    auto one = testing::Render(testing::RoomWithRoofWindow(), kMaterials, config, 1, 1);
    auto many = testing::Render(testing::RoomWithRoofWindow(), kMaterials, config, 3, 2);
    ASSERT_TRUE(one != nullptr && many != nullptr);
    // Equal but for the order of the film's double additions (render_test.cpp's determinism
    // tests): a guide that learned differently would change every guided path.
    EXPECT_LT(testing::MaxRelativeDifference(*one->film, *many->film), 1e-12);
}

}  // namespace
}  // namespace nave::render
