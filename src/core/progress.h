#pragma once
// A progress bar with rate and ETA for long work (preprocess phases, render passes). It draws on
// stderr only when stderr is a terminal, at most a few times a second; otherwise it logs a line
// every ~10 %. Work that ends at a deadline (a render's time limit) shows the time left to it
// rather than an ETA it will never reach.

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
    /// The work ends `seconds` after the bar started at the latest (a time limit): the bar fills
    /// with the time as well as with the units, and shows the time left instead of an ETA beyond
    /// it. 0: no deadline.
    void SetDeadline(double seconds);
    /// Shows `note` after the rate and times from the next draw on ("noise 0.03"). Thread-safe.
    void SetNote(std::string note);
    /// Draws the final state and a newline. Called by the destructor if not before.
    void Finish();

    uint64_t done() const { return done_.load(std::memory_order_relaxed); }
    double ElapsedSeconds() const;
    /// How far the work is, in [0, 1]: the units done of the total, or the time to the deadline
    /// when that is further. 0 with neither a total nor a deadline.
    double Fraction() const;
    /// Seconds until the work ends: by the rate so far, or the deadline if sooner. Negative when
    /// unknown (no total and no deadline, or nothing done yet without a deadline).
    double SecondsLeft() const;

    /// Disables drawing everywhere (for --quiet and for tests).
    static void SetEnabled(bool enabled);

  private:
    void Draw(bool final_draw);
    /// SecondsLeft at `elapsed` seconds; `by_deadline` (may be null): whether the deadline comes
    /// first.
    double SecondsLeftAt(double elapsed, bool* by_deadline) const;

    std::string label_;
    std::string unit_;
    std::string note_;  // under draw_mutex_
    std::atomic<uint64_t> total_;
    std::atomic<uint64_t> done_{0};
    std::atomic<double> deadline_s_{0};
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
/// A rate per second that shows its motion however slow: "2.40 M/s", "31.0/s", "0.53/s".
std::string FormatRate(double per_second);

}  // namespace nave
