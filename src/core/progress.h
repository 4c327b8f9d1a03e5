#pragma once
// A progress bar with rate and ETA for long work (preprocess phases, render passes). It draws on
// stderr only when stderr is a terminal, at most a few times a second; otherwise it logs a line
// every ~10 %.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace nave {

class ProgressBar {
  public:
    /// `total` units of work named `unit` ("triangles", "rays"); 0 means unknown (no ETA, count
    /// only).
    ProgressBar(std::string label, uint64_t total, std::string unit);
    ~ProgressBar();
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    /// Adds `n` done units. Thread-safe and cheap: drawing is throttled.
    void Add(uint64_t n);
    /// Sets the total once it becomes known.
    void SetTotal(uint64_t total);
    /// Shows `note` after the rate and times from the next draw on ("noise 0.03"). Thread-safe.
    void SetNote(std::string note);
    /// Draws the final state and a newline. Called by the destructor if not before.
    void Finish();

    uint64_t done() const { return done_.load(std::memory_order_relaxed); }
    double ElapsedSeconds() const;

    /// Disables drawing everywhere (for --quiet and for tests).
    static void SetEnabled(bool enabled);

  private:
    void Draw(bool final_draw);

    std::string label_;
    std::string unit_;
    std::string note_;  // under draw_mutex_
    std::atomic<uint64_t> total_;
    std::atomic<uint64_t> done_{0};
    std::chrono::steady_clock::time_point start_;
    std::atomic<int64_t> last_draw_ns_{0};
    int last_logged_decile_ = -1;
    std::mutex draw_mutex_;
    bool finished_ = false;
    bool tty_ = false;
};

/// "3.2 s", "4 min 05 s", "1 h 02 min".
std::string FormatDuration(double seconds);
/// "1.5 M" style counts for rates and totals.
std::string FormatCount(double count);

}  // namespace nave
