#include "src/core/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "src/core/log.h"

namespace nave {
namespace {
std::atomic<bool> g_enabled{true};
constexpr int64_t kRedrawIntervalNs = 200'000'000;  // 5 redraws per second at most
}  // namespace

void ProgressBar::SetEnabled(bool enabled) { g_enabled.store(enabled); }

ProgressBar::ProgressBar(std::string label, uint64_t total, std::string unit)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      start_(std::chrono::steady_clock::now()),
      tty_(isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() { Finish(); }

double ProgressBar::ElapsedSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressBar::SetTotal(uint64_t total) { total_.store(total); }

void ProgressBar::SetDeadline(double seconds) { deadline_s_.store(std::max(0.0, seconds)); }

double ProgressBar::Fraction() const {
    const uint64_t total = total_.load();
    double fraction = total > 0 ? std::min(1.0, double(done_.load()) / double(total)) : 0.0;
    const double deadline = deadline_s_.load();
    if (deadline > 0) fraction = std::max(fraction, std::min(1.0, ElapsedSeconds() / deadline));
    return fraction;
}

double ProgressBar::SecondsLeft() const { return SecondsLeftAt(ElapsedSeconds(), nullptr); }

double ProgressBar::SecondsLeftAt(double elapsed, bool* by_deadline) const {
    const uint64_t done = done_.load(), total = total_.load();
    double left = -1;
    if (total > 0 && done > 0 && elapsed > 0) {
        left = double(total - std::min(done, total)) / (double(done) / elapsed);
    }
    const double deadline = deadline_s_.load();
    const double to_deadline = std::max(0.0, deadline - elapsed);
    const bool deadline_first = deadline > 0 && (left < 0 || to_deadline < left);
    if (by_deadline != nullptr) *by_deadline = deadline_first;
    return deadline_first ? to_deadline : left;
}

void ProgressBar::Add(uint64_t n) {
    done_.fetch_add(n, std::memory_order_relaxed);
    if (!g_enabled.load(std::memory_order_relaxed)) return;
    int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::steady_clock::now() - start_)
                      .count();
    int64_t last = last_draw_ns_.load(std::memory_order_relaxed);
    if (now - last < kRedrawIntervalNs) return;
    if (!last_draw_ns_.compare_exchange_strong(last, now)) return;  // another thread draws
    Draw(false);
}

void ProgressBar::Finish() {
    {
        std::lock_guard lock(draw_mutex_);
        if (finished_) return;
    }
    if (g_enabled.load()) Draw(true);
    std::lock_guard lock(draw_mutex_);
    finished_ = true;
}

void ProgressBar::SetNote(std::string note) {
    std::lock_guard lock(draw_mutex_);
    note_ = std::move(note);
}

void ProgressBar::Draw(bool final_draw) {
    std::lock_guard lock(draw_mutex_);
    if (finished_) return;
    const uint64_t done = done_.load();
    const uint64_t total = total_.load();
    const double elapsed = ElapsedSeconds();
    const double rate = elapsed > 0 ? double(done) / elapsed : 0.0;
    std::string tail = fmt::format("{} {} | {} | {}", FormatCount(double(done)), unit_,
                                   FormatRate(rate), FormatDuration(elapsed));
    const double deadline = deadline_s_.load();
    // Past a deadline (a render stopped by its time limit) the bar is full: the limit, not the
    // units, was its measure.
    const double fraction = Fraction();
    bool by_deadline = false;
    const double left = SecondsLeftAt(elapsed, &by_deadline);
    if (!final_draw && left >= 0) {
        tail += fmt::format(" | {} {}", by_deadline ? "time left" : "ETA", FormatDuration(left));
    }
    if (!note_.empty()) tail += " | " + note_;
    if (tty_) {
        constexpr int kWidth = 30;
        std::string bar;
        if (total > 0 || deadline > 0) {
            const int filled = std::clamp(int(fraction * kWidth), 0, kWidth);
            bar = fmt::format("[{:#<{}}{:-<{}}] {:5.1f}% ", "", filled, "", kWidth - filled,
                              100.0 * fraction);
        }
        std::fprintf(stderr, "\r\033[K%s %s%s%s", label_.c_str(), bar.c_str(), tail.c_str(),
                     final_draw ? "\n" : "");
        std::fflush(stderr);
    } else {
        // Not a terminal (CI logs, pipes): one line per 10 % and a final one.
        const bool measured = total > 0 || deadline > 0;
        int decile = measured ? int(fraction * 10) : -1;
        if (final_draw || (decile > last_logged_decile_ && decile < 10)) {
            last_logged_decile_ = decile;
            if (measured)
                log::Info("{} {:5.1f}% {}", label_, 100.0 * fraction, tail);
            else if (final_draw)
                log::Info("{} {}", label_, tail);
        }
    }
}

std::string FormatDuration(double seconds) {
    if (seconds < 60) return fmt::format("{:.1f} s", seconds);
    const long long s = std::llround(seconds);
    if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
    return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

std::string FormatRate(double per_second) {
    if (per_second >= 1e4) return FormatCount(per_second) + "/s";
    if (per_second >= 10) return fmt::format("{:.1f}/s", per_second);
    if (per_second >= 1) return fmt::format("{:.2f}/s", per_second);
    return fmt::format("{:.3f}/s", per_second);
}

std::string FormatCount(double count) {
    if (count >= 1e9) return fmt::format("{:.2f} G", count / 1e9);
    if (count >= 1e6) return fmt::format("{:.2f} M", count / 1e6);
    if (count >= 1e4) return fmt::format("{:.1f} k", count / 1e3);
    return fmt::format("{:.0f}", count);
}

}  // namespace nave
