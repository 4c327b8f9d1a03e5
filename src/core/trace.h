#pragma once
// Timelines of a run in the Chrome trace event format (JSON), for https://ui.perfetto.dev and
// chrome://tracing: spans of work per thread ("X" complete events), counters ("C"), instants ("i")
// and thread names ("M" metadata). Events are kept in memory and written once at the end by
// Write().
//
// Disabled tracing is a null TraceRecorder*: every call site tests the pointer (TraceSpan does it
// for you), so a run without --trace pays one branch per site and never reads the clock.
//
//   TraceRecorder trace;                          // or a null TraceRecorder* when tracing is off
//   trace.NameThread("main");
//   {
//       TraceSpan span(&trace, "load brick", "pager");
//       ...
//       span.AddArg({"brick", brick_id});
//       span.AddArg({"bytes", compressed_bytes});
//   }                                             // the span ends here
//   trace.Counter("pager", {{"resident_bytes", resident}, {"budget_bytes", budget}});
//   NAVE_RETURN_IF_ERROR(trace.Write("render.trace.json"));

#include <chrono>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <variant>
#include <vector>

#include "src/core/status.h"

namespace nave {

/// One argument of an event: a key and an integer, a floating-point number or a string. A view: the
/// key and a string value are copied when the event is recorded, so temporaries are fine.
struct TraceArg {
    template <std::integral T>
    TraceArg(std::string_view k, T v) : key(k), value(static_cast<int64_t>(v)) {}
    template <std::floating_point T>
    TraceArg(std::string_view k, T v) : key(k), value(static_cast<double>(v)) {}
    TraceArg(std::string_view k, std::string_view v) : key(k), value(v) {}

    std::string_view key;
    /// Unsigned values above INT64_MAX wrap (not expected for counts and bytes).
    std::variant<int64_t, double, std::string_view> value;
};

/// One series of a counter event: a name and a number (counters in the format take numbers only).
struct TraceSeries {
    template <std::integral T>
    TraceSeries(std::string_view n, T v) : name(n), value(static_cast<double>(v)) {}
    template <std::floating_point T>
    TraceSeries(std::string_view n, T v) : name(n), value(static_cast<double>(v)) {}

    std::string_view name;
    double value;
};

/// Collects trace events from any number of threads and writes them as one Chrome trace JSON file.
///
/// Thread safety: every method may be called from any thread at any time, Write() included
/// (recording threads wait while Write() copies the events). Events go under one mutex into flat
/// arrays with interned names; a call costs a lock, a hash lookup of the thread and an append
/// (amortized; string argument values are copied). Threads get small ids 1, 2, ... in the order
/// they first record or name themselves.
///
/// Memory is bounded: once `max_events` events (complete, counter and instant; thread names do not
/// count) are held, later ones are dropped and counted; Write() reports the count in the file (an
/// instant "trace events dropped" at the first drop and a "trace_dropped_events" metadata event).
class TraceRecorder {
  public:
    using Clock = std::chrono::steady_clock;
    /// 2 million events take 80 MB in memory plus 48 bytes per argument (twice that while Write()
    /// copies them) and about 250 MB of JSON.
    static constexpr size_t kDefaultMaxEvents = 2'000'000;

    /// Time 0 of the trace is the construction of the recorder.
    explicit TraceRecorder(size_t max_events = kDefaultMaxEvents);
    TraceRecorder(const TraceRecorder&) = delete;
    TraceRecorder& operator=(const TraceRecorder&) = delete;

    /// A span of work on the calling thread, from `start` to `end` as measured by the caller (an
    /// `end` before `start` is recorded with duration 0). `name` is what the span is ("load
    /// brick"), `category` the part of nave it belongs to ("pager", "integrator").
    void Complete(std::string_view name, std::string_view category, Clock::time_point start,
                  Clock::time_point end, std::initializer_list<TraceArg> args = {});
    /// A counter sampled now: one track per `name`, one line per series.
    void Counter(std::string_view name, std::initializer_list<TraceSeries> series);
    /// A point in time on the calling thread's track.
    void Instant(std::string_view name, std::string_view category,
                 std::initializer_list<TraceArg> args = {});
    /// Names the calling thread's track ("main", "worker 3", "prefetch"); the last name given wins.
    void NameThread(std::string_view name);
    /// The process the trace shows its threads under: its id in the file (the operating system's
    /// process id unless set) and its name ("nave"). Traces of several processes written with
    /// distinct ids merge into one view (docs/distributed.md, "Traces").
    void NameProcess(int id, std::string_view name);

    /// Writes every event recorded so far to `path` (through AtomicFile: the file appears complete
    /// or not at all). Events are sorted by start time, enclosing spans before the spans they
    /// contain. Errors are IoError naming the path (missing directory, full disk).
    Status Write(const std::filesystem::path& path) const;

    /// Events held (not counting thread names).
    size_t event_count() const;
    /// Events refused because `max_events` were already held.
    uint64_t dropped_events() const;
    size_t max_events() const { return max_events_; }

  private:
    friend class TraceSpan;

    enum class Phase : char { kComplete = 'X', kCounter = 'C', kInstant = 'i' };
    struct Event {
        int64_t ts_ns;   // start, from origin_
        int64_t dur_ns;  // complete events only
        uint32_t name;   // index into names_
        uint32_t category;
        uint32_t tid;
        uint32_t args_begin;  // into args_ (complete, instant) or series_ (counter)
        uint32_t args_count;
        Phase phase;
    };
    struct StoredArg {
        uint32_t key;  // index into names_
        std::variant<int64_t, double, std::string> value;
    };
    struct StoredSeries {
        uint32_t name;
        double value;
    };

    void RecordComplete(std::string_view name, std::string_view category, Clock::time_point start,
                        Clock::time_point end, std::span<const TraceArg> args);
    /// Reserves a slot for one event, or counts a drop and returns false. Requires mutex_.
    bool Admit(Clock::time_point now);
    uint32_t Intern(std::string_view text);                         // requires mutex_
    uint32_t ThreadId();                                            // requires mutex_
    void AppendArgs(Event& event, std::span<const TraceArg> args);  // requires mutex_
    int64_t Nanoseconds(Clock::time_point t) const {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(t - origin_).count();
    }

    const size_t max_events_;
    const Clock::time_point origin_;
    mutable std::mutex mutex_;
    std::vector<Event> events_;
    std::vector<StoredArg> args_;
    std::vector<StoredSeries> series_;
    std::vector<std::string> names_;
    std::map<std::string, uint32_t, std::less<>> name_ids_;
    std::unordered_map<std::thread::id, uint32_t> thread_ids_;
    std::map<uint32_t, std::string> thread_names_;
    int process_id_;  // NameProcess, else getpid()
    std::string process_name_ = "nave";
    uint64_t dropped_ = 0;
    int64_t first_drop_ns_ = 0;
    uint32_t first_drop_tid_ = 0;
};

/// Records a complete event on `recorder` from construction to destruction (or End()) on the
/// calling thread. A null `recorder` makes it free: no clock read, no lock. `name` and `category`
/// are viewed, not copied, until the span ends: pass string literals or strings that outlive the
/// span. Not thread-safe itself (one thread owns a span); not copyable or movable.
class TraceSpan {
  public:
    TraceSpan(TraceRecorder* recorder, std::string_view name, std::string_view category)
        : recorder_(recorder), name_(name), category_(category) {
        if (recorder_) start_ = TraceRecorder::Clock::now();
    }
    ~TraceSpan() { End(); }
    TraceSpan(const TraceSpan&) = delete;
    TraceSpan& operator=(const TraceSpan&) = delete;

    /// Adds an argument shown with the span (brick id, triangles, bytes); copied now.
    void AddArg(const TraceArg& arg);
    /// Ends the span now; later calls and the destructor do nothing.
    void End() {
        if (recorder_) Finish();
    }

  private:
    void Finish();

    TraceRecorder* recorder_;
    std::string_view name_;
    std::string_view category_;
    TraceRecorder::Clock::time_point start_;
    // Owned copies, since a TraceArg is a view that may not live until the span ends.
    std::vector<std::pair<std::string, std::variant<int64_t, double, std::string>>> args_;
};

}  // namespace nave
