#include "src/render/transport/path_guide.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <tuple>
#include <type_traits>
#include <utility>

#include "src/core/byte_stream.h"
#include "src/core/check.h"
#include "src/core/sampling.h"
#include "src/render/stream/ray.h"

namespace nave::render {
namespace {

// Of a guided cell's distribution, this share is uniform over the sphere: every bin keeps a
// little probability, so that the guide never starves a direction that its cell has not yet
// seen light from (the BSDF's share samples every direction too).
constexpr double kUniformShare = 0.1;

/// The solid-angle pdf of bin `bin` of a cell's CDF: its probability over its solid angle,
/// 4π / kBins.
float BinPdf(const float* cdf, int bin) {
    return (cdf[bin] - (bin > 0 ? cdf[bin - 1] : 0.f)) * float(PathGuide::kBins) / (4 * kPi);
}

/// PathGuide::Cell::since_round of the cells the constructor gives histograms: every round credits
/// them.
constexpr int32_t kBeforeRounds = -2;

}  // namespace

struct PathGuide::Cell {
    uint64_t sum[kBins] = {};  // fixed-point credits per bin, of the oldest open round too
    /// The cumulative distribution over the bins that the last Update of an even round made
    /// (kEveryUpdate: of every round); Overlap::cdf holds the odd rounds'.
    float cdf[kBins] = {};
    uint32_t credits = 0;
    uint32_t pending_credits = 0;
    /// The Update (its round) that gave the cell its histogram (kBeforeRounds: the guide's
    /// constructor): the rounds that began before it count their credits in the level's counts.
    int32_t since_round = 0;
    bool guiding[2] = {false, false};  // the Update of that parity gave it a distribution
};

/// What a cell needs beside Cell when rounds overlap (kDoublingPasses), kept apart so that photon
/// mode's gather guide, whose rounds never overlap, does not hold it.
struct PathGuide::Overlap {
    uint64_t pending[kBins] = {};  // credits of the round after the oldest open one
    float cdf[kBins] = {};         // the distribution that the last Update of an odd round made
};

float* PathGuide::CdfOf(uint32_t slot, int parity) const {
    return parity == 0 ? cells_[slot]->cdf : overlap_[slot]->cdf;
}

void PathGuide::AddCell(int32_t since_round) {
    cells_.push_back(std::make_unique<Cell>());
    cells_.back()->since_round = since_round;
    if (rounds_ == GuideRounds::kDoublingPasses) overlap_.push_back(std::make_unique<Overlap>());
}

PathGuide::PathGuide(const Bounds3f& bounds, int coarse_cells_long_axis, uint32_t max_cells,
                     double radiance_scale, GuideRounds rounds)
    : bounds_(bounds), max_cells_(max_cells), rounds_(rounds) {
    NAVE_CHECK(!bounds.Empty());
    NAVE_CHECK(coarse_cells_long_axis > 0 && coarse_cells_long_axis <= 64);
    const Vec3f d = bounds.Diagonal();
    const float extent[3] = {std::max(d.x, 1e-6f), std::max(d.y, 1e-6f), std::max(d.z, 1e-6f)};
    const float coarse =
        std::max({extent[0], extent[1], extent[2]}) / float(coarse_cells_long_axis);
    for (int l = 0; l < kLevels; ++l) {
        Level& level = levels_[l];
        level.size = 1;
        for (int a = 0; a < 3; ++a) {
            level.res[a] = std::clamp(int(std::ceil(extent[a] / coarse)), 1, coarse_cells_long_axis)
                           << l;
            level.size *= uint32_t(level.res[a]);
        }
        level.size *= kSides;
        level.slot = std::make_unique<uint32_t[]>(level.size);
        std::fill_n(level.slot.get(), level.size, kNoCell);
        level.count = std::make_unique<uint32_t[]>(level.size);  // zeroed
        if (rounds == GuideRounds::kDoublingPasses)
            level.pending_count = std::make_unique<uint32_t[]>(level.size);  // zeroed
    }
    // CreditKey packs the finest slot index in 24 bits.
    NAVE_CHECK(levels_[kLevels - 1].size <= (1u << 24));
    const float per_metre = float(1 << (kLevels - 1)) / coarse;  // finest cells per unit length
    inv_fine_cell_ = Vec3f(per_metre, per_metre, per_metre);
    // A credit of the scene's radiance scale is 2^32 units: sums of millions of credits stay far
    // from 2^64, and a credit a millionth of the scale still has 4000 units.
    to_fixed_ = 0x1p32 / std::max(radiance_scale, 1e-30);
    cells_.reserve(max_cells_);
    if (rounds_ == GuideRounds::kDoublingPasses) overlap_.reserve(max_cells_);
    // With rounds that begin before the one two rounds back has ended, a cell given its
    // histogram by the Update closing round 0 (at pass 4) learns from round 2 on and guides from
    // round 4 (pass 16): the coarse cells, when they take at most half the cap, have theirs from
    // the start, so that round 0's paths teach them and round 2's (passes 4-7) are guided by them.
    if (rounds_ == GuideRounds::kDoublingPasses && levels_[0].size <= max_cells_ / 2) {
        for (uint32_t i = 0; i < levels_[0].size; ++i) {
            levels_[0].slot[i] = uint32_t(cells_.size());
            AddCell(kBeforeRounds);
        }
    }
}

PathGuide::~PathGuide() = default;

uint64_t PathGuide::MemoryBytes(int coarse_cells_long_axis, uint32_t max_cells,
                                GuideRounds rounds) {
    // At most the grid's index and count per cell of each level (the bounds' other axes as long as
    // the longest at worst), and the histograms.
    uint64_t grid = 0;
    for (int l = 0; l < kLevels; ++l) {
        const uint64_t res = uint64_t(coarse_cells_long_axis) << l;
        // Its slots and counts, and the pending counts of overlapping rounds.
        const uint64_t arrays = rounds == GuideRounds::kDoublingPasses ? 3 : 2;
        grid += res * res * res * kSides * arrays * sizeof(uint32_t);
    }
    uint64_t per_cell = sizeof(Cell) + sizeof(std::unique_ptr<Cell>);
    if (rounds == GuideRounds::kDoublingPasses)
        per_cell += sizeof(Overlap) + sizeof(std::unique_ptr<Overlap>);
    return grid + uint64_t(max_cells) * per_cell;
}

bool PathGuide::FineCoords(const Vec3f& p, int xyz[3]) const {
    if (!bounds_.Contains(p)) return false;
    const Vec3f q = (p - bounds_.min);
    const int* res = levels_[kLevels - 1].res;
    xyz[0] = std::min(int(q.x * inv_fine_cell_.x), res[0] - 1);
    xyz[1] = std::min(int(q.y * inv_fine_cell_.y), res[1] - 1);
    xyz[2] = std::min(int(q.z * inv_fine_cell_.z), res[2] - 1);
    return true;
}

uint32_t PathGuide::IndexAt(int level, const int xyz[3], int side) const {
    const int shift = kLevels - 1 - level;
    const int* res = levels_[level].res;
    const uint32_t cell =
        uint32_t(((xyz[2] >> shift) * res[1] + (xyz[1] >> shift)) * res[0] + (xyz[0] >> shift));
    return cell * kSides + uint32_t(side);
}

int PathGuide::SideOf(const Vec3f& n) {
    const float a[3] = {std::abs(n.x), std::abs(n.y), std::abs(n.z)};
    const int axis = a[0] >= a[1] && a[0] >= a[2] ? 0 : (a[1] >= a[2] ? 1 : 2);
    const float v = axis == 0 ? n.x : (axis == 1 ? n.y : n.z);
    return 2 * axis + (v < 0);
}

int PathGuide::BinOf(const Vec3f& w) {
    const int zi = std::clamp(int((w.z + 1.f) * 0.5f * kZBins), 0, kZBins - 1);
    float phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi;
    const int pi = std::clamp(int(phi * (0.5f * kInvPi) * kPhiBins), 0, kPhiBins - 1);
    return zi * kPhiBins + pi;
}

uint32_t PathGuide::CreditKey(const Vec3f& p, int side, const Vec3f& w) const {
    static_assert(kBins == 256, "CreditKey packs the bin in 8 bits");
    int xyz[3];
    if (!FineCoords(p, xyz)) return kNoCredit;
    return IndexAt(kLevels - 1, xyz, side) << 8 | uint32_t(BinOf(w));
}

uint32_t PathGuide::RoundOf(uint32_t pass) const {
    return rounds_ == GuideRounds::kDoublingPasses ? RoundOfPass(pass) : rounds_closed_;
}

void PathGuide::Credit(uint32_t key, double value, uint32_t pass) {
    if (key == kNoCredit || !(value > 0)) return;
    const uint32_t round = RoundOf(pass);
    // A round credits the cells that had histograms when it began (the Update Lag() rounds
    // before it), whenever its credits arrive: the sums then do not depend on when the Update
    // in between happened.
    NAVE_CHECK(round >= rounds_closed_ && round <= rounds_closed_ + 1)
        << "a credit of round " << round << " while round " << rounds_closed_
        << " is the oldest open";
    const bool oldest = Oldest(round);
    const Level& fine = levels_[kLevels - 1];
    const int side = int((key >> 8) % kSides);
    const uint32_t g = (key >> 8) / kSides;
    const int xyz[3] = {int(g % uint32_t(fine.res[0])),
                        int(g / uint32_t(fine.res[0]) % uint32_t(fine.res[1])),
                        int(g / (uint32_t(fine.res[0]) * uint32_t(fine.res[1])))};
    // Clamped so that no single credit can overflow a bin: a rare path with a tiny pdf would
    // otherwise dominate its cell.
    const uint64_t units = uint64_t(std::min(value * to_fixed_, 0x1p40));
    for (int l = 0; l < kLevels; ++l) {
        const uint32_t index = IndexAt(l, xyz, side);
        const uint32_t slot = levels_[l].slot[index];
        if (slot == kNoCell || int64_t(cells_[slot]->since_round) > int64_t(round) - Lag()) {
            uint32_t* count = oldest ? levels_[l].count.get() : levels_[l].pending_count.get();
            std::atomic_ref<uint32_t>(count[index]).fetch_add(1, std::memory_order_relaxed);
            continue;
        }
        Cell& cell = *cells_[slot];
        std::atomic_ref<uint64_t>((oldest ? cell.sum : overlap_[slot]->pending)[key & 0xff])
            .fetch_add(units, std::memory_order_relaxed);
        std::atomic_ref<uint32_t>(oldest ? cell.credits : cell.pending_credits)
            .fetch_add(1, std::memory_order_relaxed);
    }
}

void PathGuide::Update(uint32_t min_credits) {
    const uint32_t closing = rounds_closed_;
    const int parity = int(closing % uint32_t(Lag()));
    cells_guiding_ = 0;
    for (uint32_t slot = 0; slot < cells_.size(); ++slot) {
        Cell& cell = *cells_[slot];
        double total = 0;
        for (uint64_t s : cell.sum) total += double(s);
        cell.guiding[parity] = cell.credits >= min_credits && total > 0;
        if (!cell.guiding[parity]) continue;
        ++cells_guiding_;
        float* cdf = CdfOf(slot, parity);
        double running = 0;
        for (int b = 0; b < kBins; ++b) {
            running += (1 - kUniformShare) * double(cell.sum[b]) / total + kUniformShare / kBins;
            cdf[b] = float(running);
        }
        cdf[kBins - 1] = 1.f;
    }
    // New histograms for the cells most credited so far, in an order that depends on the counts
    // alone (ties: coarser level, then lower index).
    struct Candidate {
        uint32_t count;
        int level;
        uint32_t index;
    };
    std::vector<Candidate> candidates;
    // A cell made now learns from the next round (kEveryUpdate) or only from the second round
    // after this one (kDoublingPasses: the next is under way already), and guides one Update
    // later still: there, a cell is made as soon as anything credited it.
    const uint32_t min_count =
        rounds_ == GuideRounds::kDoublingPasses ? 1u : std::max(1u, min_credits / 4);
    for (int l = 0; l < kLevels; ++l) {
        for (uint32_t i = 0; i < levels_[l].size; ++i) {
            if (levels_[l].slot[i] == kNoCell && levels_[l].count[i] >= min_count)
                candidates.push_back({levels_[l].count[i], l, i});
        }
    }
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
        return std::tie(b.count, a.level, a.index) < std::tie(a.count, b.level, b.index);
    });
    for (const Candidate& c : candidates) {
        if (cells_.size() >= max_cells_) break;
        levels_[c.level].slot[c.index] = uint32_t(cells_.size());
        AddCell(int32_t(closing));
    }
    // The round after the closed one is the oldest open one now: what it credited so far joins
    // the sums, and its later credits go there directly.
    for (Level& level : levels_) {
        if (!level.pending_count) continue;
        for (uint32_t i = 0; i < level.size; ++i) {
            level.count[i] += level.pending_count[i];
            level.pending_count[i] = 0;
        }
    }
    for (uint32_t slot = 0; slot < overlap_.size(); ++slot) {
        Cell& c = *cells_[slot];
        for (int b = 0; b < kBins; ++b) c.sum[b] += std::exchange(overlap_[slot]->pending[b], 0);
        c.credits += std::exchange(c.pending_credits, 0);
    }
    ++rounds_closed_;
    // Every process holds the same credits after the sums that precede an Update in a
    // distributed render, and makes the same Update: what is shared is what it holds now.
    if (!shared_.empty()) shared_ = FlatCredits();
}

template <class Guide, class F>
void PathGuide::ForEachCredit(Guide& self, F&& f) {
    for (auto& level : self.levels_) {
        for (uint32_t i = 0; i < level.size; ++i) f(level.count[i]);
        if (!level.pending_count) continue;
        for (uint32_t i = 0; i < level.size; ++i) f(level.pending_count[i]);
    }
    for (uint32_t slot = 0; slot < self.cells_.size(); ++slot) {
        auto& cell = *self.cells_[slot];
        for (int b = 0; b < kBins; ++b) f(cell.sum[b]);
        f(cell.credits);
        if (slot < self.overlap_.size()) {
            for (int b = 0; b < kBins; ++b) f(self.overlap_[slot]->pending[b]);
            f(cell.pending_credits);
        }
    }
}

std::vector<uint64_t> PathGuide::FlatCredits() const {
    std::vector<uint64_t> values;
    ForEachCredit(*this, [&](auto value) { values.push_back(uint64_t(value)); });
    return values;
}

Status PathGuide::ShareCredits(const std::function<Status(std::span<uint64_t>)>& sum) {
    std::vector<uint64_t> values = FlatCredits();
    const size_t size = values.size();
    shared_.resize(size, 0);  // new cells: nothing shared yet
    for (size_t i = 0; i < size; ++i) values[i] -= shared_[i];
    NAVE_RETURN_IF_ERROR(sum(values));
    for (size_t i = 0; i < size; ++i) shared_[i] += values[i];
    size_t at = 0;
    ForEachCredit(*this, [&](auto& value) {
        value = static_cast<std::remove_reference_t<decltype(value)>>(shared_[at++]);
    });
    return Status::Ok();
}

void PathGuide::SaveState(ByteWriter* out) const {
    out->Put(rounds_closed_);
    for (const Level& level : levels_) {
        out->PutArray(level.slot.get(), level.size);
        out->PutArray(level.count.get(), level.size);
        if (level.pending_count) out->PutArray(level.pending_count.get(), level.size);
    }
    out->Put(uint32_t(cells_.size()));
    for (uint32_t slot = 0; slot < cells_.size(); ++slot) {
        const std::unique_ptr<Cell>& cell = cells_[slot];
        out->Put(cell->sum);
        out->Put(cell->cdf);
        if (slot < overlap_.size()) {
            out->Put(overlap_[slot]->pending);
            out->Put(overlap_[slot]->cdf);
        }
        out->Put(cell->credits);
        out->Put(cell->pending_credits);
        out->Put(cell->since_round);
        out->Put(uint8_t(cell->guiding[0] | cell->guiding[1] << 1));
    }
    out->Put(cells_guiding_);
}

Status PathGuide::LoadState(ByteReader* in) {
    NAVE_RETURN_IF_ERROR(in->Get(&rounds_closed_, "guide rounds closed"));
    for (Level& level : levels_) {
        NAVE_RETURN_IF_ERROR(in->GetArray(level.slot.get(), level.size, "guide cell slots"));
        NAVE_RETURN_IF_ERROR(in->GetArray(level.count.get(), level.size, "guide cell counts"));
        if (level.pending_count) {
            NAVE_RETURN_IF_ERROR(
                in->GetArray(level.pending_count.get(), level.size, "guide cell pending counts"));
        }
    }
    uint32_t cells = 0;
    NAVE_RETURN_IF_ERROR(in->Get(&cells, "guide cell count"));
    if (cells > max_cells_) {
        return DataLossError("{}: {} guide cells, at most {} expected", in->what(), cells,
                             max_cells_);
    }
    for (const Level& level : levels_) {
        for (uint32_t i = 0; i < level.size; ++i) {
            if (level.slot[i] != kNoCell && level.slot[i] >= cells) {
                return DataLossError("{}: guide slot {} points at cell {} of {}", in->what(), i,
                                     level.slot[i], cells);
            }
        }
    }
    cells_.clear();
    overlap_.clear();
    for (uint32_t c = 0; c < cells; ++c) {
        AddCell(0);
        Cell* cell = cells_.back().get();
        uint8_t guiding = 0;
        NAVE_RETURN_IF_ERROR(in->Get(&cell->sum, "guide cell sums"));
        NAVE_RETURN_IF_ERROR(in->Get(&cell->cdf, "guide cell distribution"));
        if (!overlap_.empty()) {
            NAVE_RETURN_IF_ERROR(in->Get(&overlap_.back()->pending, "guide cell pending sums"));
            NAVE_RETURN_IF_ERROR(in->Get(&overlap_.back()->cdf, "guide cell odd distribution"));
        }
        NAVE_RETURN_IF_ERROR(in->Get(&cell->credits, "guide cell credits"));
        NAVE_RETURN_IF_ERROR(in->Get(&cell->pending_credits, "guide cell pending credits"));
        NAVE_RETURN_IF_ERROR(in->Get(&cell->since_round, "guide cell round"));
        NAVE_RETURN_IF_ERROR(in->Get(&guiding, "guide cell flags"));
        cell->guiding[0] = (guiding & 1) != 0;
        cell->guiding[1] = (guiding & 2) != 0;
    }
    NAVE_RETURN_IF_ERROR(in->Get(&cells_guiding_, "guiding cell count"));
    // What a checkpoint holds is every process's credits together (a distributed render shares
    // them before it writes one): each process that resumes from it shares only what it credits
    // after.
    shared_ = FlatCredits();
    return Status::Ok();
}

const float* PathGuide::Distribution(const Vec3f& p, int side, uint32_t pass) const {
    // The Update whose distributions pass `pass` samples: the one closing round (its round -
    // Lag()). kEveryUpdate: the last one.
    const int64_t made_by = int64_t(RoundOf(pass)) - Lag();
    if (made_by < 0) return nullptr;
    const int parity = int(made_by % Lag());
    int xyz[3];
    if (!FineCoords(p, xyz)) return nullptr;
    for (int l = kLevels - 1; l >= 0; --l) {
        const uint32_t slot = levels_[l].slot[IndexAt(l, xyz, side)];
        // A cell given its histogram by a later Update than made_by has not guided at made_by:
        // its flag of that parity was cleared when it was made and is set again only by an
        // Update after every round sampling made_by's has begun.
        if (slot != kNoCell && cells_[slot]->guiding[parity]) return CdfOf(slot, parity);
    }
    return nullptr;
}

std::optional<GuideSample> PathGuide::Sample(const Vec3f& p, int side, float u_bin, float u0,
                                             float u1, uint32_t pass) const {
    const float* cdf = Distribution(p, side, pass);
    if (cdf == nullptr) return std::nullopt;
    const int bin = int(std::upper_bound(cdf, cdf + kBins - 1, u_bin) - cdf);
    // Uniform within the bin: cos θ and φ are uniform in it (equal-area cylindrical mapping,
    // Archimedes' hat-box theorem).
    const int z_bin = bin / kPhiBins;
    const float z = std::clamp(-1.f + 2.f * (float(z_bin) + u0) / kZBins, -1.f, 1.f);
    const float phi = 2 * kPi * (float(bin % kPhiBins) + u1) / kPhiBins;
    const float r = std::sqrt(std::max(0.f, 1 - z * z));
    const Vec3f wi(r * std::cos(phi), r * std::sin(phi), z);
    // The pdf of the bin the direction falls in as Pdf sees it (rounding at a bin's edge can move
    // it to the neighbour): the sample's pdf and Pdf must agree for MIS.
    return GuideSample{wi, BinPdf(cdf, BinOf(wi))};
}

float PathGuide::Pdf(const Vec3f& p, int side, const Vec3f& w, uint32_t pass) const {
    const float* cdf = Distribution(p, side, pass);
    if (cdf == nullptr) return 0;
    return BinPdf(cdf, BinOf(w));
}

float GuidedBsdf::Pdf(const Vec3f& wo, const Vec3f& wi, const SampledWavelengths& lambda) const {
    const float bsdf_pdf = bsdf_.Pdf(wo, wi, lambda);
    if (guide_ == nullptr) return bsdf_pdf;
    return kGuideShare * guide_->Pdf(p_, side_, wi, pass_) + (1 - kGuideShare) * bsdf_pdf;
}

std::optional<BsdfSample> GuidedBsdf::Sample(const Vec3f& wo, float u_choice, float uc, Point2f u,
                                             const std::array<float, 3>& ug,
                                             const SampledWavelengths& lambda) const {
    if (guide_ == nullptr) return bsdf_.Sample(wo, uc, u, lambda);
    if (u_choice < kGuideShare) {
        std::optional<GuideSample> g = guide_->Sample(p_, side_, ug[0], ug[1], ug[2], pass_);
        if (!g) return std::nullopt;
        BsdfSample s;
        s.wi = g->wi;
        s.f = bsdf_.Eval(wo, s.wi, lambda);
        if (s.f.IsZero()) return std::nullopt;  // below a reflecting surface, say
        s.pdf = kGuideShare * g->pdf + (1 - kGuideShare) * bsdf_.Pdf(wo, s.wi, lambda);
        if (!(s.pdf > 0)) return std::nullopt;
        // The flags of a non-specular BSDF's lobes for this direction: reflection or transmission
        // by the side of the shading frame, diffuse or glossy as the BSDF has them.
        const bool reflect = Dot(wo, bsdf_.frame().z) * Dot(s.wi, bsdf_.frame().z) > 0;
        s.flags = uint8_t((bsdf_.Flags() & (kBxdfDiffuse | kBxdfGlossy)) |
                          (reflect ? kBxdfReflection : kBxdfTransmission));
        return s;
    }
    std::optional<BsdfSample> s = bsdf_.Sample(wo, uc, u, lambda);
    if (!s) return std::nullopt;
    s->pdf = kGuideShare * guide_->Pdf(p_, side_, s->wi, pass_) + (1 - kGuideShare) * s->pdf;
    return s;
}

}  // namespace nave::render
