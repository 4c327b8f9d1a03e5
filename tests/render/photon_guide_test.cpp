#include "src/render/transport/photon_guide.h"

#include <gtest/gtest.h>

#include <vector>

#include "src/render/transport/rng.h"

namespace nave::render {
namespace {

TEST(PhotonGuideTest, CellsCoverTheSquareAndNothingElse) {
    PhotonGuide guide(4, 2.f);  // cells of 1 m over [-2, 2]^2
    EXPECT_EQ(guide.Cell(-1.9f, -1.9f), 0);
    EXPECT_EQ(guide.Cell(1.9f, -1.9f), 3);
    EXPECT_EQ(guide.Cell(-1.9f, 1.9f), 12);
    EXPECT_EQ(guide.Cell(0.5f, 0.5f), 2 * 4 + 2);
    EXPECT_EQ(guide.Cell(2.1f, 0), PhotonGuide::kNoCell);
    EXPECT_EQ(guide.Cell(0, -2.1f), PhotonGuide::kNoCell);
    EXPECT_FALSE(guide.trained());
    EXPECT_EQ(guide.Pdf(0, 0), 0.f);
}

// After learning that cell 5 brought three times the light of cell 10 (and the rest none), the
// guide draws three quarters of its points in cell 5, one quarter in cell 10, with densities that
// integrate to one: 0.75 and 0.25 per m^2 over cells of 1 m^2.
TEST(PhotonGuideTest, SamplesInProportionToWhatWasLearned) {
    PhotonGuide guide(4, 2.f);
    const std::vector<uint16_t> cells = {5, 10, 5, PhotonGuide::kNoCell, 7};
    const std::vector<float> deposited = {2.f, 1.f, 1.f, 100.f, 0.f};
    guide.Learn(cells, deposited);
    ASSERT_TRUE(guide.trained());
    EXPECT_FLOAT_EQ(guide.Pdf(-0.5f, -0.5f), 0.75f);  // cell 5: i = 1, j = 1
    EXPECT_FLOAT_EQ(guide.Pdf(0.5f, 0.5f), 0.25f);    // cell 10
    EXPECT_EQ(guide.Pdf(1.5f, -0.5f), 0.f);           // cell 7 brought nothing
    int in_five = 0, in_ten = 0;
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
        VertexRng rng(RngKey{1, uint32_t(k), 0, 0, 0, 0});
        const Point2f p = guide.Sample(rng.Uniform(0), Point2f(rng.Uniform(1), rng.Uniform(2)));
        const uint16_t c = guide.Cell(p.x, p.y);
        ASSERT_TRUE(c == 5 || c == 10) << c;
        (c == 5 ? in_five : in_ten) += 1;
    }
    EXPECT_NEAR(double(in_five) / n, 0.75, 0.015);
    EXPECT_NEAR(double(in_ten) / n, 0.25, 0.015);
}

TEST(PhotonGuideTest, LearningAccumulatesOverPasses) {
    PhotonGuide guide(2, 1.f);
    guide.Learn(std::vector<uint16_t>{0}, std::vector<float>{1.f});
    EXPECT_FLOAT_EQ(guide.Pdf(-0.5f, -0.5f), 1.f);
    guide.Learn(std::vector<uint16_t>{3}, std::vector<float>{1.f});
    EXPECT_FLOAT_EQ(guide.Pdf(-0.5f, -0.5f), 0.5f);
    EXPECT_FLOAT_EQ(guide.Pdf(0.5f, 0.5f), 0.5f);
}

}  // namespace
}  // namespace nave::render
