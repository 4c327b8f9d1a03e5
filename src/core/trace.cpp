#include "src/core/trace.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <type_traits>

#include "src/core/file.h"
#include "src/core/json_string.h"

namespace nave {
namespace {

// The JSON is built in pieces of about this size and appended to the file, so that a trace of
// millions of events never needs its whole text in memory.
constexpr size_t kFlushBytes = 1 << 20;

/// JSON has no NaN or infinity: they become null (the viewers show the key with no value).
void AppendJsonNumber(std::string& out, double value) {
    if (std::isfinite(value)) {
        fmt::format_to(std::back_inserter(out), "{}", value);
    } else {
        out += "null";
    }
}

/// Microseconds (the format's unit) with nanosecond digits.
void AppendMicroseconds(std::string& out, int64_t ns) {
    if (ns < 0) {
        out += '-';
        ns = -ns;
    }
    fmt::format_to(std::back_inserter(out), "{}.{:03d}", ns / 1000, ns % 1000);
}

}  // namespace

TraceRecorder::TraceRecorder(size_t max_events)
    : max_events_(max_events), origin_(Clock::now()), process_id_(int(::getpid())) {}

bool TraceRecorder::Admit(Clock::time_point now) {
    if (events_.size() < max_events_) return true;
    if (dropped_ == 0) {
        first_drop_ns_ = Nanoseconds(now);
        first_drop_tid_ = ThreadId();
    }
    ++dropped_;
    return false;
}

uint32_t TraceRecorder::Intern(std::string_view text) {
    auto it = name_ids_.find(text);
    if (it != name_ids_.end()) return it->second;
    auto id = static_cast<uint32_t>(names_.size());
    names_.emplace_back(text);
    name_ids_.emplace(std::string(text), id);
    return id;
}

uint32_t TraceRecorder::ThreadId() {
    auto [it, inserted] = thread_ids_.try_emplace(std::this_thread::get_id(), 0);
    if (inserted) it->second = static_cast<uint32_t>(thread_ids_.size());
    return it->second;
}

void TraceRecorder::AppendArgs(Event& event, std::span<const TraceArg> args) {
    event.args_begin = static_cast<uint32_t>(args_.size());
    event.args_count = static_cast<uint32_t>(args.size());
    for (const TraceArg& arg : args) {
        StoredArg stored{Intern(arg.key), int64_t{0}};
        std::visit(
            [&](const auto& v) {
                if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string_view>) {
                    stored.value = std::string(v);
                } else {
                    stored.value = v;
                }
            },
            arg.value);
        args_.push_back(std::move(stored));
    }
}

void TraceRecorder::Complete(std::string_view name, std::string_view category,
                             Clock::time_point start, Clock::time_point end,
                             std::initializer_list<TraceArg> args) {
    RecordComplete(name, category, start, end,
                   std::span<const TraceArg>(args.begin(), args.size()));
}

void TraceRecorder::RecordComplete(std::string_view name, std::string_view category,
                                   Clock::time_point start, Clock::time_point end,
                                   std::span<const TraceArg> args) {
    std::lock_guard lock(mutex_);
    if (!Admit(end)) return;
    Event event{};
    event.phase = Phase::kComplete;
    event.ts_ns = Nanoseconds(start);
    event.dur_ns = std::max<int64_t>(0, Nanoseconds(end) - event.ts_ns);
    event.name = Intern(name);
    event.category = Intern(category);
    event.tid = ThreadId();
    AppendArgs(event, args);
    events_.push_back(event);
}

void TraceRecorder::Counter(std::string_view name, std::initializer_list<TraceSeries> series) {
    Clock::time_point now = Clock::now();
    std::lock_guard lock(mutex_);
    if (!Admit(now)) return;
    Event event{};
    event.phase = Phase::kCounter;
    event.ts_ns = Nanoseconds(now);
    event.name = Intern(name);
    event.category = Intern("counter");
    event.tid = ThreadId();
    event.args_begin = static_cast<uint32_t>(series_.size());
    event.args_count = static_cast<uint32_t>(series.size());
    for (const TraceSeries& s : series) series_.push_back({Intern(s.name), s.value});
    events_.push_back(event);
}

void TraceRecorder::Instant(std::string_view name, std::string_view category,
                            std::initializer_list<TraceArg> args) {
    Clock::time_point now = Clock::now();
    std::lock_guard lock(mutex_);
    if (!Admit(now)) return;
    Event event{};
    event.phase = Phase::kInstant;
    event.ts_ns = Nanoseconds(now);
    event.name = Intern(name);
    event.category = Intern(category);
    event.tid = ThreadId();
    AppendArgs(event, std::span<const TraceArg>(args.begin(), args.size()));
    events_.push_back(event);
}

void TraceRecorder::NameThread(std::string_view name) {
    std::lock_guard lock(mutex_);
    thread_names_[ThreadId()] = std::string(name);
}

void TraceRecorder::NameProcess(int id, std::string_view name) {
    std::lock_guard lock(mutex_);
    process_id_ = id;
    process_name_ = std::string(name);
}

size_t TraceRecorder::event_count() const {
    std::lock_guard lock(mutex_);
    return events_.size();
}

uint64_t TraceRecorder::dropped_events() const {
    std::lock_guard lock(mutex_);
    return dropped_;
}

Status TraceRecorder::Write(const std::filesystem::path& path) const {
    // Copied under the lock so that threads still recording wait only for the copy, not for the
    // disk.
    std::vector<Event> events;
    std::vector<StoredArg> args;
    std::vector<StoredSeries> series;
    std::vector<std::string> names;
    std::map<uint32_t, std::string> thread_names;
    int pid;
    std::string process_name;
    uint64_t dropped;
    int64_t first_drop_ns;
    uint32_t first_drop_tid;
    {
        std::lock_guard lock(mutex_);
        events = events_;
        args = args_;
        series = series_;
        names = names_;
        thread_names = thread_names_;
        pid = process_id_;
        process_name = process_name_;
        dropped = dropped_;
        first_drop_ns = first_drop_ns_;
        first_drop_tid = first_drop_tid_;
    }

    // By start time, and at equal starts the longer span first: viewers nest a span under the one
    // listed before it, and per-thread timestamps come out in order for tools that expect it.
    std::vector<uint32_t> order(events.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        if (events[a].ts_ns != events[b].ts_ns) return events[a].ts_ns < events[b].ts_ns;
        return events[a].dur_ns > events[b].dur_ns;
    });

    auto file = AtomicFile::Create(path);
    if (!file.ok())
        return file.status().WithContext(fmt::format("writing trace {}", path.string()));

    std::string out;
    out.reserve(kFlushBytes + 4096);
    auto flush = [&]() -> Status {
        Status status = file->Write(out);
        out.clear();
        return status.WithContext(fmt::format("writing trace {}", path.string()));
    };
    bool first = true;
    auto begin_event = [&](std::string_view name, char phase, uint32_t tid) {
        out += first ? "\n" : ",\n";
        first = false;
        out += "{\"name\":";
        AppendJsonString(out, name);
        fmt::format_to(std::back_inserter(out), ",\"ph\":\"{}\",\"pid\":{},\"tid\":{}", phase, pid,
                       tid);
    };

    out += "{\"traceEvents\":[";
    begin_event("process_name", 'M', 0);
    out += ",\"args\":{\"name\":";
    AppendJsonString(out, process_name);
    out += "}}";
    for (const auto& [tid, name] : thread_names) {
        begin_event("thread_name", 'M', tid);
        out += ",\"args\":{\"name\":";
        AppendJsonString(out, name);
        out += "}}";
    }
    if (dropped > 0) {
        // A metadata record for tools here, and after the events a global instant that the viewers
        // draw across every track at the moment the trace stopped being complete.
        begin_event("trace_dropped_events", 'M', 0);
        fmt::format_to(std::back_inserter(out),
                       ",\"args\":{{\"dropped_events\":{},\"max_events\":{}}}}}", dropped,
                       max_events_);
    }

    for (uint32_t index : order) {
        const Event& e = events[index];
        begin_event(names[e.name], static_cast<char>(e.phase), e.tid);
        out += ",\"cat\":";
        AppendJsonString(out, names[e.category]);
        out += ",\"ts\":";
        AppendMicroseconds(out, e.ts_ns);
        if (e.phase == Phase::kComplete) {
            out += ",\"dur\":";
            AppendMicroseconds(out, e.dur_ns);
        }
        if (e.phase == Phase::kInstant) out += ",\"s\":\"t\"";
        out += ",\"args\":{";
        for (uint32_t i = 0; i < e.args_count; ++i) {
            if (i > 0) out += ',';
            if (e.phase == Phase::kCounter) {
                const StoredSeries& s = series[e.args_begin + i];
                AppendJsonString(out, names[s.name]);
                out += ':';
                AppendJsonNumber(out, s.value);
                continue;
            }
            const StoredArg& a = args[e.args_begin + i];
            AppendJsonString(out, names[a.key]);
            out += ':';
            if (const auto* text = std::get_if<std::string>(&a.value)) {
                AppendJsonString(out, *text);
            } else if (const auto* integer = std::get_if<int64_t>(&a.value)) {
                fmt::format_to(std::back_inserter(out), "{}", *integer);
            } else {
                AppendJsonNumber(out, std::get<double>(a.value));
            }
        }
        out += "}}";
        if (out.size() >= kFlushBytes) NAVE_RETURN_IF_ERROR(flush());
    }
    if (dropped > 0) {
        begin_event("trace events dropped", 'i', first_drop_tid);
        out += ",\"cat\":\"trace\",\"s\":\"g\",\"ts\":";
        AppendMicroseconds(out, first_drop_ns);
        fmt::format_to(std::back_inserter(out),
                       ",\"args\":{{\"dropped_events\":{},\"max_events\":{}}}}}", dropped,
                       max_events_);
    }
    out += "\n],\"displayTimeUnit\":\"ms\"}\n";
    NAVE_RETURN_IF_ERROR(flush());
    return file->Commit().WithContext(fmt::format("writing trace {}", path.string()));
}

void TraceSpan::AddArg(const TraceArg& arg) {
    if (!recorder_) return;
    std::variant<int64_t, double, std::string> value;
    std::visit(
        [&](const auto& v) {
            if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string_view>) {
                value = std::string(v);
            } else {
                value = v;
            }
        },
        arg.value);
    args_.emplace_back(std::string(arg.key), std::move(value));
}

void TraceSpan::Finish() {
    TraceRecorder::Clock::time_point end = TraceRecorder::Clock::now();
    std::vector<TraceArg> views;
    views.reserve(args_.size());
    // Not a structured binding: clang before 16 (the fuzz preset's) cannot capture one in a lambda.
    for (const auto& arg : args_) {
        std::visit([&](const auto& v) { views.emplace_back(arg.first, v); }, arg.second);
    }
    recorder_->RecordComplete(name_, category_, start_, end, views);
    recorder_ = nullptr;
}

}  // namespace nave
