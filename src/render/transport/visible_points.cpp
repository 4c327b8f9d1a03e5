#include "src/render/transport/visible_points.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <numeric>
#include <type_traits>

#include "src/core/atomic_add.h"
#include "src/core/byte_stream.h"
#include "src/core/color.h"
#include "src/render/scene/scene.h"
#include "src/render/stream/ray_exchange.h"
#include "src/render/transport/rng.h"
#include "src/render/transport/transport_common.h"

namespace nave::render {

VisiblePoints::VisiblePoints(size_t pixel_count, uint32_t brick_count, float initial_radius,
                             float alpha, bool caustic_points)
    : points_(pixel_count * (caustic_points ? 2 : 1)),
      pixels_(new PixelState[pixel_count]),
      pixel_count_(pixel_count),
      radius_(initial_radius),
      alpha_(alpha),
      grids_(brick_count) {
    for (size_t i = 0; i < pixel_count; ++i) {
        for (auto& f : pixels_[i].phi) f.store(0, std::memory_order_relaxed);
    }
}

bool UsesCausticPoints(const RenderSettings& settings,
                       const std::vector<SurfaceMaterial>& materials) {
    return settings.mode == RenderSettings::Mode::kPhoton && settings.final_gather &&
           std::any_of(materials.begin(), materials.end(),
                       [](const SurfaceMaterial& m) { return m.MakesCaustics(); });
}

SampledWavelengths IterationWavelengths(uint64_t seed, uint32_t iteration, int channel) {
    const VertexRng rng(RngKey{seed, uint32_t(channel), 0, 0, iteration, kStreamWavelengths});
    return SampledWavelengths::SampleVisible(rng.Uniform(0));
}

void VisiblePoints::BeginIteration(uint64_t seed, uint32_t iteration, uint64_t photons) {
    const uint64_t n_shared = PhotonChannel(0, photons) != kOwnWavelengths
                                  ? (photons + kSharedWavelengthEvery - 1) / kSharedWavelengthEvery
                                  : 0;
    for (uint32_t c = 0; c < kWavelengthChannels; ++c) {
        shared_lambda_[c] = IterationWavelengths(seed, iteration, int(c));
        // Shared photons k, 2k, 3k... go to channels 0, 1, 2... in turn.
        const uint64_t n_c = n_shared / kWavelengthChannels + (c < n_shared % kWavelengthChannels);
        shared_weight_[c] = n_c > 0 ? float(double(photons) / double(n_c)) : 0.f;
    }
    own_weight_ = float(double(photons) / double(photons - n_shared));
    for (Point& p : points_) p.valid = false;
    for (BrickGrid& g : grids_) g.cells.clear();
}

void VisiblePoints::Add(uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo,
                        const SurfaceMaterial& material, const std::array<float, 2>* uv,
                        const imaging::TextureFootprint& footprint, const SampledSpectrum& beta,
                        const SampledWavelengths& lambda) {
    Set(&points_[pixel], pixel, p, ns, wo, material, uv, footprint, beta, lambda);
}

void VisiblePoints::AddCaustic(uint32_t pixel, const Vec3f& p, const Vec3f& ns, const Vec3f& wo,
                               const SurfaceMaterial& material, const std::array<float, 2>* uv,
                               const imaging::TextureFootprint& footprint,
                               const SampledSpectrum& beta, const SampledWavelengths& lambda) {
    Set(&points_[pixel_count_ + pixel], pixel, p, ns, wo, material, uv, footprint, beta, lambda);
}

void VisiblePoints::Set(Point* point, uint32_t pixel, const Vec3f& p, const Vec3f& ns,
                        const Vec3f& wo, const SurfaceMaterial& material,
                        const std::array<float, 2>* uv, const imaging::TextureFootprint& footprint,
                        const SampledSpectrum& beta, const SampledWavelengths& lambda) {
    Point& vp = *point;
    vp.footprint = footprint;
    vp.has_uv = uv != nullptr;
    if (uv != nullptr) vp.uv = *uv;
    vp.p = p;
    vp.ns = ns;
    vp.wo = wo;
    vp.material = &material;
    vp.valid = true;
    bool flat = true;
    for (int i = 1; i < kNumWavelengths; ++i) flat = flat && beta[i] == beta[0];
    if (lambda.SecondaryTerminated()) {
        const bool shared =
            lambda.lambda_nm(0) == shared_lambda_[size_t(PixelChannel(pixel))].lambda_nm(0);
        vp.throughput = shared ? Throughput::kHeroShared : Throughput::kHeroOnly;
        vp.beta_nm.fill(beta[0]);
    } else if (flat) {
        vp.throughput = Throughput::kFlat;
        vp.beta_nm.fill(beta[0]);
    } else {
        vp.throughput = Throughput::kInterpolated;
        std::array<int, kNumWavelengths> order;
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return lambda.lambda_nm(a) < lambda.lambda_nm(b); });
        for (int i = 0; i < kNumWavelengths; ++i) {
            vp.lambda_nm[i] = lambda.lambda_nm(order[i]);
            vp.beta_nm[i] = beta[order[i]];
        }
    }
}

SampledSpectrum VisiblePoints::Point::ThroughputAt(const SampledWavelengths& lambda) const {
    if (throughput == Throughput::kFlat) return SampledSpectrum(beta_nm[0]);
    SampledSpectrum s;
    for (int k = 0; k < kNumWavelengths; ++k) {
        const float l = lambda.lambda_nm(k);
        // Linear between the camera path's wavelengths, constant beyond the first and the last: an
        // approximation for the smooth spectra of glass and metals (visible_points.h).
        if (l <= lambda_nm[0]) {
            s[k] = beta_nm[0];
        } else if (l >= lambda_nm[kNumWavelengths - 1]) {
            s[k] = beta_nm[kNumWavelengths - 1];
        } else {
            int i = 1;
            while (lambda_nm[i] < l) ++i;
            const float t =
                (l - lambda_nm[i - 1]) / std::max(1e-6f, lambda_nm[i] - lambda_nm[i - 1]);
            s[k] = beta_nm[i - 1] + t * (beta_nm[i] - beta_nm[i - 1]);
        }
    }
    return s;
}

uint64_t VisiblePoints::CellKey(const Vec3f& p, float cell) const {
    int64_t x = int64_t(std::floor(p.x / cell)), y = int64_t(std::floor(p.y / cell)),
            z = int64_t(std::floor(p.z / cell));
    return HashCombine(HashCombine(MixBits(uint64_t(x)), uint64_t(y)), uint64_t(z));
}

Bounds3f VisiblePoints::GatherBox(const Vec3f& p) const {
    const float r = radius_;
    return Bounds3f(p - Vec3f(r, r, r), p + Vec3f(r, r, r));
}

namespace {

// A visible point on its way to another process: its index among the points and its material's
// among the scene's, then the point itself with its material pointer cleared.
struct WireHeader {
    uint32_t index;
    uint32_t material;
};

}  // namespace

Status VisiblePoints::ShareWithOwners(RankGroup& ranks, const store::BrickTree& tree,
                                      const std::function<int(uint32_t)>& owner,
                                      std::span<const SurfaceMaterial> materials) {
    static_assert(std::is_trivially_copyable_v<Point>);
    constexpr size_t kWireBytes = sizeof(WireHeader) + sizeof(Point);
    const auto size = static_cast<size_t>(ranks.size());
    const int me = ranks.rank();
    std::vector<std::vector<std::byte>> to_rank(size);
    std::vector<uint32_t> bricks;
    std::vector<bool> sent(size);
    for (size_t i = 0; i < points_.size(); ++i) {
        const Point& vp = points_[i];
        if (!vp.valid || radius_ <= 0) continue;
        tree.BricksOverlapping(GatherBox(vp.p), &bricks);
        std::fill(sent.begin(), sent.end(), false);
        for (uint32_t b : bricks) {
            const int r = owner(b);
            if (r == me || sent[size_t(r)]) continue;
            sent[size_t(r)] = true;
            const WireHeader header{uint32_t(i), uint32_t(vp.material - materials.data())};
            Point copy = vp;
            copy.material = nullptr;
            std::vector<std::byte>& out = to_rank[size_t(r)];
            const size_t at = out.size();
            out.resize(at + kWireBytes);
            std::memcpy(out.data() + at, &header, sizeof(header));
            std::memcpy(out.data() + at + sizeof(header), &copy, sizeof(copy));
        }
    }
    NAVE_ASSIGN_OR_RETURN(const std::vector<std::byte> received, ranks.SendToEach(to_rank));
    to_rank.clear();
    if (received.size() % kWireBytes != 0) {
        return InternalError("visible points from the other processes: {} bytes, not whole points",
                             received.size());
    }
    for (size_t at = 0; at < received.size(); at += kWireBytes) {
        WireHeader header;
        std::memcpy(&header, received.data() + at, sizeof(header));
        if (header.index >= points_.size() || header.material >= materials.size()) {
            return InternalError(
                "a visible point from another process: point {} of {}, material {} of {}",
                header.index, points_.size(), header.material, materials.size());
        }
        // One camera path per pixel: no other process made this pixel's point.
        Point& vp = points_[header.index];
        std::memcpy(&vp, received.data() + at + sizeof(header), sizeof(Point));
        vp.material = &materials[header.material];
    }
    return Status::Ok();
}

void VisiblePoints::BuildBrickGrids(const store::BrickTree& tree,
                                    const std::function<bool(uint32_t)>& keep) {
    if (radius_ <= 0) return;
    for (BrickGrid& g : grids_) g.cell = 2 * radius_;
    std::vector<uint32_t> bricks;
    // In the points' order, whichever process made them: a cell lists its points in the same order
    // in every process, and a photon adds to them in that order.
    for (size_t i = 0; i < points_.size(); ++i) {
        const Point& vp = points_[i];
        if (!vp.valid) continue;
        const Bounds3f box = GatherBox(vp.p);
        tree.BricksOverlapping(box, &bricks);
        for (uint32_t b : bricks) {
            if (keep && !keep(b)) continue;
            BrickGrid& g = grids_[b];
            int lo[3], hi[3];
            for (int a = 0; a < 3; ++a) {
                lo[a] = int(std::floor(box.min[a] / g.cell));
                hi[a] = int(std::floor(box.max[a] / g.cell));
            }
            for (int z = lo[2]; z <= hi[2]; ++z)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        Vec3f c((float(x) + 0.5f) * g.cell, (float(y) + 0.5f) * g.cell,
                                (float(z) + 0.5f) * g.cell);
                        g.cells[CellKey(c, g.cell)].push_back(uint32_t(i));
                    }
        }
    }
}

float VisiblePoints::Deposit(uint32_t brick, const Vec3f& p, const Vec3f& ng, const Vec3f& wi,
                             const SampledSpectrum& beta, const SampledWavelengths& lambda,
                             int channel, bool caustic) {
    const BrickGrid& g = grids_[brick];
    auto it = g.cells.find(CellKey(p, g.cell));
    if (it == g.cells.end()) return 0;
    float added = 0;
    for (uint32_t i : it->second) {
        // Caustic points follow the visible points, a pixel's at pixel_count_ + pixel.
        const bool caustic_point = i >= pixel_count_;
        if (caustic_point && !caustic) continue;
        const uint32_t pixel = caustic_point ? uint32_t(i - pixel_count_) : i;
        const Point& vp = points_[i];
        PixelState& px = pixels_[pixel];
        Vec3f d = vp.p - p;
        if (Dot(d, d) > radius_ * radius_) continue;
        if (vp.throughput == Throughput::kHeroOnly) continue;
        if ((vp.throughput == Throughput::kHeroShared) != (channel != kOwnWavelengths)) continue;
        if (channel != kOwnWavelengths && PixelChannel(pixel) != channel) continue;
        if (std::abs(Dot(ng, vp.ns)) < kSameSurfaceCos) continue;
        Vec3d xyz;
        if (vp.throughput == Throughput::kHeroShared) {
            // The camera path's one wavelength is the shared hero, which this photon carries at its
            // index 0 (terminated or not).
            SampledWavelengths l = shared_lambda_[size_t(channel)];
            l.TerminateSecondary();
            SampledSpectrum f =
                vp.material->MakeBsdf(vp.ns, &l, vp.has_uv ? &vp.uv : nullptr, vp.footprint)
                    .Eval(vp.wo, wi, l);
            SampledSpectrum c;
            c[0] = vp.beta_nm[0] * f[0] * beta[0] * shared_weight_[size_t(channel)];
            if (c.IsZero()) continue;
            xyz = SampledToXYZ(c, l);
        } else {
            SampledWavelengths l = lambda;
            SampledSpectrum f =
                vp.material->MakeBsdf(vp.ns, &l, vp.has_uv ? &vp.uv : nullptr, vp.footprint)
                    .Eval(vp.wo, wi, l);
            if (f.IsZero()) continue;
            xyz = SampledToXYZ(vp.ThroughputAt(l) * f * beta * own_weight_, l);
        }
        for (int c = 0; c < 3; ++c) AtomicAdd(px.phi[c], xyz[c]);
        added += float(xyz.y);
        deposits_.fetch_add(1, std::memory_order_relaxed);
    }
    return added;
}

void VisiblePoints::EndIteration(int half) {
    const double area = std::numbers::pi * double(radius_) * radius_;
    for (size_t i = 0; i < pixel_count_; ++i) {
        PixelState& px = pixels_[i];
        if (points_[i].valid || (caustic_points() && points_[pixel_count_ + i].valid)) {
            Vec3d density;
            for (int c = 0; c < 3; ++c)
                density[c] = px.phi[c].load(std::memory_order_relaxed) / area;
            px.density_sum += density;
            if (half == 0) px.density_sum_y_half0 += density.y;
        }
        for (auto& f : px.phi) f.store(0, std::memory_order_relaxed);
    }
    // Knaus & Zwicker 2011 eq. 16: r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1).
    radius_ *= float(std::sqrt((iteration_ + double(alpha_)) / (iteration_ + 1.0)));
    ++iteration_;
}

void VisiblePoints::SaveState(ByteWriter* out) const {
    out->Put(radius_);
    out->Put(int32_t(iteration_));
    out->Put(deposits_.load(std::memory_order_relaxed));
    std::vector<double> sums(pixel_count_ * 4);
    for (size_t i = 0; i < pixel_count_; ++i) {
        for (int c = 0; c < 3; ++c) sums[4 * i + c] = pixels_[i].density_sum[c];
        sums[4 * i + 3] = pixels_[i].density_sum_y_half0;
    }
    out->PutArray(sums.data(), sums.size());
}

Status VisiblePoints::LoadState(ByteReader* in) {
    int32_t iteration = 0;
    uint64_t deposits = 0;
    NAVE_RETURN_IF_ERROR(in->Get(&radius_, "radius"));
    NAVE_RETURN_IF_ERROR(in->Get(&iteration, "iteration"));
    NAVE_RETURN_IF_ERROR(in->Get(&deposits, "deposits"));
    std::vector<double> sums(pixel_count_ * 4);
    NAVE_RETURN_IF_ERROR(in->GetArray(sums.data(), sums.size(), "pixel density sums"));
    if (!(radius_ > 0) || iteration < 1) {
        return DataLossError(
            "{}: radius {} at iteration {}, expected a positive radius from "
            "iteration 1 on",
            in->what(), radius_, iteration);
    }
    iteration_ = iteration;
    deposits_.store(deposits, std::memory_order_relaxed);
    for (size_t i = 0; i < pixel_count_; ++i) {
        for (int c = 0; c < 3; ++c) pixels_[i].density_sum[c] = sums[4 * i + c];
        pixels_[i].density_sum_y_half0 = sums[4 * i + 3];
    }
    return in->ExpectEnd();
}

Status VisiblePoints::CombineSums(const std::function<Status(std::span<double>)>& sum) {
    // The deposits' count rides along, exact in a double up to 2^53.
    std::vector<double> sums(pixel_count_ * 4 + 1);
    for (size_t i = 0; i < pixel_count_; ++i) {
        for (int c = 0; c < 3; ++c) sums[4 * i + c] = pixels_[i].density_sum[c];
        sums[4 * i + 3] = pixels_[i].density_sum_y_half0;
    }
    sums.back() = double(deposits_.load(std::memory_order_relaxed));
    NAVE_RETURN_IF_ERROR(sum(sums));
    for (size_t i = 0; i < pixel_count_; ++i) {
        for (int c = 0; c < 3; ++c) pixels_[i].density_sum[c] = sums[4 * i + c];
        pixels_[i].density_sum_y_half0 = sums[4 * i + 3];
    }
    deposits_.store(uint64_t(sums.back()), std::memory_order_relaxed);
    return Status::Ok();
}

void VisiblePoints::ClearSums() {
    for (size_t i = 0; i < pixel_count_; ++i) {
        pixels_[i].density_sum = Vec3d();
        pixels_[i].density_sum_y_half0 = 0;
    }
    deposits_.store(0, std::memory_order_relaxed);
}

Vec3d VisiblePoints::IndirectXYZ(uint32_t pixel, double photons_emitted) const {
    if (photons_emitted <= 0) return {};
    return pixels_[pixel].density_sum * (1.0 / photons_emitted);
}

double VisiblePoints::IndirectHalfY(uint32_t pixel, int half, double photons_emitted) const {
    if (photons_emitted <= 0) return 0;
    const PixelState& px = pixels_[pixel];
    const double y = half == 0 ? px.density_sum_y_half0 : px.density_sum.y - px.density_sum_y_half0;
    return y / photons_emitted;
}

}  // namespace nave::render
