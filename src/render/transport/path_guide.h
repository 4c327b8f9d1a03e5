#pragma once
// Path guiding for path mode: where, seen from a point of the model, the light that paths bring
// back comes from, learned during the render from the paths' own contributions and sampled beside
// the BSDF (one-sample MIS). Inside the abbey most of the light reaching a wall has been reflected
// once by a sunlit patch of floor; a BSDF-sampled path finds such patches by chance, a guided path
// learns where they are.
//
// The guide is three nested grids of cells over the model's bounds, each cell a histogram of
// incident radiance over the sphere of directions (equal-area bins: cos θ and φ uniform); a point
// is guided by its finest cell that has learned enough, so that rarely visited places use coarse
// cells and busy ones fine cells. Credits are summed in fixed point, and cells get histograms only
// at updates, so the learned distributions do not depend on the order in which threads add them:
// the image stays independent of the thread count and the memory budget.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "src/core/byte_stream.h"
#include "src/core/spectrum.h"
#include "src/core/status.h"
#include "src/core/vecmath.h"
#include "src/render/scene/materials/bxdf.h"

namespace nave::render {

/// Path mode's guide: coarse cells of about a twelfth of the model's longest axis (8 m in the
/// abbey), halved twice (2 m), at most 8192 of them with histograms (60 MB with the grids and the
/// second sums and distributions that overlapping rounds need (GuideRounds), in the
/// memory reserve).
inline constexpr int kGuideCoarseCellsLongAxis = 12;
inline constexpr uint32_t kGuideMaxCells = 8192;
/// Photon mode's gather guide (final gathering): half as many cells, 19 MB, beside the visible
/// points, the photons' learning and the windows in the memory reserve.
inline constexpr uint32_t kGatherGuideMaxCells = 4096;

/// A direction drawn from a guide cell, with its solid-angle pdf.
struct GuideSample {
    Vec3f wi;
    float pdf = 0;
};

/// How a guide's learning is split into rounds, each closed by an Update, and which distributions
/// a path samples.
enum class GuideRounds {
    /// Every Update closes the round in progress, and what is sampled next is what it made:
    /// credits and samples need no pass (photon mode's gather guide: an Update per iteration,
    /// after a complete drain).
    kEveryUpdate,
    /// Rounds of passes that double after two of two (passes 0-1 | 2-3 | 4-7 | 8-15 ...,
    /// RoundOfPass), and a pass of round r samples what the Update closing round r - 2 made (none
    /// before round 2, pass 4). Round r
    /// may then start while round r - 1's last rays are still in flight, and only round r - 2
    /// must have ended: a render under a memory budget overlaps the tail of one round, scattered
    /// over many bricks, with the next round's rays instead of draining it to the last ray
    /// (docs/render.md, "Path guiding").
    kDoublingPasses,
};

/// Incident-radiance histograms over three nested grids of cells (each cell of a level split in
/// 2 x 2 x 2 at the next), the finest guiding where enough paths credit it. Credit is thread-safe
/// and may run while paths are sampled; Update is not concurrent with anything (call it between
/// two batches, always at the same points of the render: which cells get histograms and what
/// each round samples depend only on the credits of the rounds before, never on when a credit
/// arrived, so the image does not depend on threads or the memory budget).
class PathGuide {
  public:
    /// Bins per cell: kZBins in cos θ (θ from +z) times kPhiBins in φ; every bin covers the same
    /// solid angle, 4π / kBins.
    static constexpr int kZBins = 16;
    static constexpr int kPhiBins = 16;
    static constexpr int kBins = kZBins * kPhiBins;
    static constexpr int kLevels = 3;
    /// A credit key that credits nothing.
    static constexpr uint32_t kNoCredit = 0xffffffffu;

    /// A guide over `bounds` with coarse cells of about the longest axis /
    /// `coarse_cells_long_axis`, at most `max_cells` of them (over the levels) holding histograms.
    /// `radiance_scale`: a radiance of the scene's order (a sunlit white wall's, or the sky's),
    /// which sets the fixed-point resolution of the credits. `rounds`: how Update splits the
    /// learning (GuideRounds).
    PathGuide(const Bounds3f& bounds, int coarse_cells_long_axis, uint32_t max_cells,
              double radiance_scale, GuideRounds rounds = GuideRounds::kEveryUpdate);
    ~PathGuide();
    PathGuide(const PathGuide&) = delete;
    PathGuide& operator=(const PathGuide&) = delete;

    /// Bytes the guide holds at most for `max_cells` cells, `coarse_cells_long_axis` and `rounds`
    /// (the render's memory reserve).
    static uint64_t MemoryBytes(int coarse_cells_long_axis, uint32_t max_cells,
                                GuideRounds rounds = GuideRounds::kEveryUpdate);

    /// Histograms are kept apart by the side a surface faces (SideOf): a floor and the wall above
    /// it in one cell see different halves of the sphere.
    static constexpr int kSides = 6;
    /// The side of a surface whose normal, turned toward the path, is `n`: its largest axis and
    /// that axis' sign.
    static int SideOf(const Vec3f& n);
    /// The side of a surface of normal `n` seen from direction `w` (pointing away from it): n
    /// turned toward w.
    static int SideSeenFrom(const Vec3f& n, const Vec3f& w) {
        return SideOf(Dot(n, w) >= 0 ? n : -n);
    }

    /// The key that credits direction `w` (unit) at point `p` on a surface of side `side`, or
    /// kNoCredit outside the grid.
    uint32_t CreditKey(const Vec3f& p, int side, const Vec3f& w) const;
    /// Adds `value` (incident radiance over the pdf it was sampled with, >= 0), learned by a path
    /// of pass `pass` (kDoublingPasses: of a round not yet closed; kEveryUpdate: ignored), to the
    /// bin of `key` in each level's cell that had a histogram when that round began, and counts
    /// the credit for the others. Thread-safe; the order of credits does not change the sums.
    void Credit(uint32_t key, double value, uint32_t pass);

    /// Closes the oldest round still open (kDoublingPasses: every pass of it must have ended;
    /// its successor may still be in flight): the credits of every closed round become the
    /// distributions that the rounds sampling this one's use (a cell guides once it holds
    /// `min_credits` credits), and the cells most credited without a histogram get one (at least
    /// `min_credits` / 4 credits, most first, up to the cap). Not concurrent with Credit,
    /// Sample or Pdf.
    void Update(uint32_t min_credits = 64);
    /// Rounds closed so far (kDoublingPasses: round rounds_closed() is the oldest open one).
    uint32_t rounds_closed() const { return rounds_closed_; }

    /// Whether a cell at `p` guides a path of pass `pass` (Sample and Pdf are then meaningful).
    bool Guides(const Vec3f& p, int side, uint32_t pass) const {
        return Distribution(p, side, pass) != nullptr;
    }
    /// A direction at `p` on a surface of side `side` from its finest cell guiding pass `pass`,
    /// and three uniform numbers; nothing if no cell there guides.
    /// No default pass: in path mode a wrong one samples another round's distribution, and the
    /// mixture's pdf then disagrees with what was sampled.
    std::optional<GuideSample> Sample(const Vec3f& p, int side, float u_bin, float u0, float u1,
                                      uint32_t pass) const;
    /// The solid-angle pdf of Sample at `p`, `side` for direction `w` (0 if no cell there guides).
    float Pdf(const Vec3f& p, int side, const Vec3f& w, uint32_t pass) const;

    /// In a distributed render (docs/distributed.md), before each Update and before a checkpoint
    /// is written: gives every process's
    /// guide the credits of all. `sum` replaces its values by their sums over the processes; each
    /// process passes what it credited since the last call, so every guide ends with the same
    /// credits, those one process would have (they are integers: the order of sums does not
    /// matter), and the same Update. Collective; not concurrent with Credit, Sample or Pdf.
    Status ShareCredits(const std::function<Status(std::span<uint64_t>)>& sum);

    /// Appends everything learned (credits, counts, cells and their distributions) to `out`, for
    /// a checkpoint; LoadState into a guide made with the same arguments restores it exactly (the
    /// credits are integers). Not concurrent with Credit or Update.
    void SaveState(ByteWriter* out) const;
    /// Replaces the guide's state with what SaveState wrote. Errors: DataLoss for another grid,
    /// more cells than the cap, or truncated bytes. Not concurrent with anything.
    Status LoadState(ByteReader* in);

    /// Cells holding histograms, and those of them guiding since the last Update.
    uint32_t cells_used() const { return uint32_t(cells_.size()); }
    uint32_t cells_guiding() const { return cells_guiding_; }

    /// The bin of unit direction `w`.
    static int BinOf(const Vec3f& w);

  private:
    struct Cell;
    struct Overlap;
    struct Level {
        int res[3] = {1, 1, 1};
        std::unique_ptr<uint32_t[]>
            slot;  // per grid cell and side: its index in cells_, or kNoCell
        std::unique_ptr<uint32_t[]> count;  // per grid cell and side without a histogram: credits
        std::unique_ptr<uint32_t[]> pending_count;  // kDoublingPasses: the same, of the round after
                                                    // the oldest open one
        uint32_t size = 0;                          // grid cells times kSides
    };
    static constexpr uint32_t kNoCell = 0xffffffffu;
    /// The finest level's cell coordinates of `p`; false outside the bounds.
    bool FineCoords(const Vec3f& p, int xyz[3]) const;
    /// The index at `level` of the histogram slot of the finest level's cell coordinates `xyz`
    /// and `side`.
    uint32_t IndexAt(int level, const int xyz[3], int side) const;
    /// The distribution (CDF over the bins) of the finest cell at `p`, `side` guiding pass
    /// `pass`, or null.
    const float* Distribution(const Vec3f& p, int side, uint32_t pass) const;
    /// The round a credit of pass `pass` belongs to.
    uint32_t RoundOf(uint32_t pass) const;
    /// Rounds between a round and the one whose Update made what it samples.
    int Lag() const { return rounds_ == GuideRounds::kDoublingPasses ? 2 : 1; }
    /// Whether round `round`'s credits are those of the oldest open round (the others, of the
    /// round after it, wait in the cells' pending sums until Update closes the oldest).
    bool Oldest(uint32_t round) const { return round <= rounds_closed_; }

    Bounds3f bounds_;
    Vec3f inv_fine_cell_;
    uint32_t max_cells_;
    double to_fixed_;  // fixed-point units per unit of credit
    GuideRounds rounds_;
    uint32_t rounds_closed_ = 0;
    Level levels_[kLevels];  // coarse to fine
    std::vector<std::unique_ptr<Cell>> cells_;
    std::vector<std::unique_ptr<Overlap>> overlap_;  // kDoublingPasses: one per cell
    /// The distribution of cell `slot` that the last Update of a round of parity `parity` made.
    float* CdfOf(uint32_t slot, int parity) const;
    /// Appends a cell (and its Overlap when rounds overlap) made by the Update of `since_round`.
    void AddCell(int32_t since_round);
    uint32_t cells_guiding_ = 0;
    /// Calls `f` on every credit the guide holds, in one fixed order: the levels' counts, then
    /// each cell's bins and credit count. Cells only ever join at the end (Update), so earlier
    /// entries keep their place. `self` is the guide, const or not; `f` takes the value by
    /// reference (uint32_t or uint64_t).
    template <class Guide, class F>
    static void ForEachCredit(Guide& self, F&& f);
    /// Everything credited, flattened as ShareCredits sums it.
    std::vector<uint64_t> FlatCredits() const;
    // The credits as of the last ShareCredits (every count, then every cell's sums and credits),
    // all processes' together: what this process credited since is its values minus these.
    std::vector<uint64_t> shared_;
};

/// A path vertex's continuation: its BSDF, mixed with the guide's distribution where the guide's
/// cell guides and the BSDF has no specular lobe (one-sample MIS with the balance heuristic: the
/// pdf of a direction is the mixture's, whichever strategy drew it). Next-event estimation weighs
/// its samples against Pdf, the escape of a continuation against the pdf Sample gave.
class GuidedBsdf {
  public:
    /// Of a guided vertex's continuations, this share is drawn from the guide.
    static constexpr float kGuideShare = 0.5f;

    /// The continuation at `p` of `bsdf` (both must outlive this) on a surface of side `side`
    /// (PathGuide::SideOf), of a path of pass `pass`; `guide` null: the BSDF alone.
    GuidedBsdf(const Bsdf& bsdf, const PathGuide* guide, const Vec3f& p, int side, uint32_t pass)
        : bsdf_(bsdf),
          guide_(guide != nullptr && !(bsdf.Flags() & kBxdfSpecular) && guide->Guides(p, side, pass)
                     ? guide
                     : nullptr),
          p_(p),
          side_(side),
          pass_(pass) {}

    bool guided() const { return guide_ != nullptr; }
    /// The solid-angle pdf with which Sample draws `wi`.
    float Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda) const;
    /// A continuation from `u_choice` (guide or BSDF), the BSDF's (uc, u) and the guide's `ug`;
    /// its pdf is the mixture's where the vertex is guided.
    std::optional<BsdfSample> Sample(const Vec3f& wo, float u_choice, float uc, Point2f u,
                                     const std::array<float, 3>& ug,
                                     const SampledWavelengths& lambda) const;

  private:
    const Bsdf& bsdf_;
    const PathGuide* guide_;
    Vec3f p_;
    int side_;
    uint32_t pass_;
};

}  // namespace nave::render
