#include "src/core/trace.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "src/core/file.h"

namespace nave {
namespace {

namespace fs = std::filesystem;

// A strict reader for the JSON the recorder writes (RFC 8259: objects, arrays, strings with every
// escape, numbers, true/false/null), so the tests check the text a viewer would parse rather than
// the recorder's own idea of it. Any syntax error fails the parse.
struct Json {
    enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject } kind = Kind::kNull;
    bool boolean = false;
    double number = 0;
    std::string string;
    std::vector<Json> array;
    std::map<std::string, Json> object;

    bool Has(const std::string& key) const { return object.count(key) != 0; }
    const Json& operator[](const std::string& key) const { return object.at(key); }
};

class JsonParser {
  public:
    explicit JsonParser(const std::string& text) : text_(text) {}

    /// The value, or nullptr with error() set.
    std::unique_ptr<Json> Parse() {
        auto value = std::make_unique<Json>();
        if (!ParseValue(*value)) return nullptr;
        SkipSpace();
        if (pos_ != text_.size()) {
            Fail("trailing characters");
            return nullptr;
        }
        return value;
    }
    const std::string& error() const { return error_; }

  private:
    bool Fail(const std::string& what) {
        error_ = what + " at offset " + std::to_string(pos_);
        return false;
    }
    void SkipSpace() {
        while (pos_ < text_.size() && std::strchr(" \t\r\n", text_[pos_]) != nullptr) ++pos_;
    }
    bool Literal(const char* word) {
        size_t n = std::strlen(word);
        if (text_.compare(pos_, n, word) != 0) return false;
        pos_ += n;
        return true;
    }
    bool ParseValue(Json& out) {
        SkipSpace();
        if (pos_ >= text_.size()) return Fail("unexpected end");
        char c = text_[pos_];
        if (c == '{') return ParseObject(out);
        if (c == '[') return ParseArray(out);
        if (c == '"') {
            out.kind = Json::Kind::kString;
            return ParseString(out.string);
        }
        if (Literal("true")) {
            out.kind = Json::Kind::kBool;
            out.boolean = true;
            return true;
        }
        if (Literal("false")) {
            out.kind = Json::Kind::kBool;
            return true;
        }
        if (Literal("null")) {
            out.kind = Json::Kind::kNull;
            return true;
        }
        return ParseNumber(out);
    }
    bool ParseNumber(Json& out) {
        // The JSON number grammar: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
        size_t start = pos_;
        auto digits = [&] {
            size_t from = pos_;
            while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])))
                ++pos_;
            return pos_ > from;
        };
        if (pos_ < text_.size() && text_[pos_] == '-') ++pos_;
        if (pos_ < text_.size() && text_[pos_] == '0') {
            ++pos_;
        } else if (!digits()) {
            return Fail("bad value");
        }
        if (pos_ < text_.size() && text_[pos_] == '.') {
            ++pos_;
            if (!digits()) return Fail("bad fraction");
        }
        if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
            ++pos_;
            if (pos_ < text_.size() && (text_[pos_] == '+' || text_[pos_] == '-')) ++pos_;
            if (!digits()) return Fail("bad exponent");
        }
        out.kind = Json::Kind::kNumber;
        out.number = std::strtod(text_.substr(start, pos_ - start).c_str(), nullptr);
        return true;
    }
    bool ParseString(std::string& out) {
        ++pos_;  // opening quote
        while (pos_ < text_.size()) {
            char c = text_[pos_++];
            if (c == '"') return true;
            if (static_cast<unsigned char>(c) < 0x20)
                return Fail("raw control character in string");
            if (c != '\\') {
                out += c;
                continue;
            }
            if (pos_ >= text_.size()) break;
            char e = text_[pos_++];
            switch (e) {
                case '"':
                    out += '"';
                    break;
                case '\\':
                    out += '\\';
                    break;
                case '/':
                    out += '/';
                    break;
                case 'b':
                    out += '\b';
                    break;
                case 'f':
                    out += '\f';
                    break;
                case 'n':
                    out += '\n';
                    break;
                case 'r':
                    out += '\r';
                    break;
                case 't':
                    out += '\t';
                    break;
                case 'u': {
                    if (pos_ + 4 > text_.size()) return Fail("short \\u escape");
                    unsigned code = std::stoul(text_.substr(pos_, 4), nullptr, 16);
                    pos_ += 4;
                    if (code >= 0x80)
                        return Fail("test reader handles \\u escapes below 0x80 only");
                    out += static_cast<char>(code);
                    break;
                }
                default:
                    return Fail(std::string("bad escape \\") + e);
            }
        }
        return Fail("unterminated string");
    }
    bool ParseArray(Json& out) {
        out.kind = Json::Kind::kArray;
        ++pos_;
        SkipSpace();
        if (pos_ < text_.size() && text_[pos_] == ']') {
            ++pos_;
            return true;
        }
        while (true) {
            out.array.emplace_back();
            if (!ParseValue(out.array.back())) return false;
            SkipSpace();
            if (pos_ < text_.size() && text_[pos_] == ',') {
                ++pos_;
                continue;
            }
            if (pos_ < text_.size() && text_[pos_] == ']') {
                ++pos_;
                return true;
            }
            return Fail("expected , or ]");
        }
    }
    bool ParseObject(Json& out) {
        out.kind = Json::Kind::kObject;
        ++pos_;
        SkipSpace();
        if (pos_ < text_.size() && text_[pos_] == '}') {
            ++pos_;
            return true;
        }
        while (true) {
            SkipSpace();
            if (pos_ >= text_.size() || text_[pos_] != '"') return Fail("expected a key");
            std::string key;
            if (!ParseString(key)) return false;
            SkipSpace();
            if (pos_ >= text_.size() || text_[pos_] != ':') return Fail("expected :");
            ++pos_;
            if (out.object.count(key) != 0) return Fail("duplicate key " + key);
            if (!ParseValue(out.object[key])) return false;
            SkipSpace();
            if (pos_ < text_.size() && text_[pos_] == ',') {
                ++pos_;
                continue;
            }
            if (pos_ < text_.size() && text_[pos_] == '}') {
                ++pos_;
                return true;
            }
            return Fail("expected , or }");
        }
    }

    const std::string& text_;
    size_t pos_ = 0;
    std::string error_;
};

class TraceTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("nave_trace_test_" + std::to_string(::getpid()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    /// Writes `trace`, checks the top level, returns the events (in file order).
    std::vector<Json> WriteAndRead(const TraceRecorder& trace) {
        fs::path path = dir_ / "trace.json";
        Status status = trace.Write(path);
        EXPECT_TRUE(status.ok()) << status.ToString();
        auto text = ReadFileToString(path);
        EXPECT_TRUE(text.ok()) << text.status().ToString();
        if (!text.ok()) return {};
        text_ = *text;
        JsonParser parser(text_);
        auto root = parser.Parse();
        EXPECT_NE(root, nullptr) << parser.error();
        if (!root) return {};
        EXPECT_EQ(root->kind, Json::Kind::kObject);
        EXPECT_EQ((*root)["displayTimeUnit"].string, "ms");
        const Json& events = (*root)["traceEvents"];
        EXPECT_EQ(events.kind, Json::Kind::kArray);
        for (const Json& e : events.array) {
            // The fields every viewer reads from every event.
            EXPECT_TRUE(e.Has("name") && e.Has("ph") && e.Has("pid") && e.Has("tid"));
            if (e["ph"].string != "M") {
                EXPECT_TRUE(e.Has("ts") && e.Has("cat"));
            }
        }
        return events.array;
    }

    static std::vector<const Json*> OfPhase(const std::vector<Json>& events,
                                            const std::string& phase) {
        std::vector<const Json*> out;
        for (const Json& e : events) {
            if (e["ph"].string == phase) out.push_back(&e);
        }
        return out;
    }

    fs::path dir_;
    std::string text_;
};

TEST_F(TraceTest, SeveralThreadsGiveOneValidTraceWithEveryEvent) {
    constexpr int kThreads = 4;
    constexpr int kSpans = 300;
    TraceRecorder trace;
    trace.NameThread("main");
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&trace, t] {
            trace.NameThread("worker " + std::to_string(t));
            for (int i = 0; i < kSpans; ++i) {
                TraceSpan outer(&trace, "render tile", "integrator");
                outer.AddArg({"tile", i});
                auto start = TraceRecorder::Clock::now();
                trace.Complete(
                    "load brick", "pager", start, TraceRecorder::Clock::now(),
                    {{"brick", t * 1000 + i}, {"bytes", uint64_t{4096}}, {"file", "abbey.nave"}});
                if (i % 10 == 0)
                    trace.Counter("pager", {{"resident_bytes", i * 100}, {"loads", i}});
            }
            trace.Instant("thread done", "integrator", {{"thread", t}});
        });
    }
    for (auto& thread : threads) thread.join();
    ASSERT_EQ(trace.dropped_events(), 0u);

    std::vector<Json> events = WriteAndRead(trace);
    ASSERT_FALSE(events.empty());
    auto complete = OfPhase(events, "X");
    auto counters = OfPhase(events, "C");
    auto instants = OfPhase(events, "i");
    auto metadata = OfPhase(events, "M");
    EXPECT_EQ(complete.size(), size_t(2 * kThreads * kSpans));
    EXPECT_EQ(counters.size(), size_t(kThreads * kSpans / 10));
    EXPECT_EQ(instants.size(), size_t(kThreads));
    EXPECT_EQ(trace.event_count(), complete.size() + counters.size() + instants.size());

    // Threads are named once each and numbered 1, 2, ... in order of first use (main first here).
    std::map<int, std::string> names;
    for (const Json* m : metadata) {
        if ((*m)["name"].string == "thread_name")
            names[int((*m)["tid"].number)] = (*m)["args"]["name"].string;
    }
    ASSERT_EQ(names.size(), size_t(kThreads + 1));
    EXPECT_EQ(names[1], "main");
    std::set<std::string> worker_names;
    for (int tid = 2; tid <= kThreads + 1; ++tid) worker_names.insert(names[tid]);
    EXPECT_EQ(worker_names,
              (std::set<std::string>{"worker 0", "worker 1", "worker 2", "worker 3"}));

    std::map<int, double> last_ts;
    std::map<int, int> spans_per_thread;
    int out_of_order = 0;
    int negative_durations = 0;
    for (const Json& e : events) {
        if (e["ph"].string == "M") continue;
        int tid = int(e["tid"].number);
        ASSERT_GE(tid, 2) << "only the workers recorded events";
        ASSERT_LE(tid, kThreads + 1);
        double ts = e["ts"].number;
        if (last_ts.count(tid) && ts < last_ts[tid]) ++out_of_order;
        last_ts[tid] = ts;
        if (e["ph"].string == "X") {
            ASSERT_TRUE(e.Has("dur"));
            if (e["dur"].number < 0) ++negative_durations;
            ++spans_per_thread[tid];
        }
    }
    EXPECT_EQ(out_of_order, 0)
        << "events whose timestamp is before the previous one on their thread";
    EXPECT_EQ(negative_durations, 0);
    for (const auto& [tid, count] : spans_per_thread)
        EXPECT_EQ(count, 2 * kSpans) << "thread " << tid;

    // Arguments of every kind survive, and a counter's series are its args.
    const Json* load = nullptr;
    for (const Json* x : complete) {
        if ((*x)["name"].string == "load brick") load = x;
    }
    ASSERT_NE(load, nullptr);
    EXPECT_EQ((*load)["cat"].string, "pager");
    EXPECT_EQ((*load)["args"]["bytes"].number, 4096.0);
    EXPECT_EQ((*load)["args"]["file"].string, "abbey.nave");
    EXPECT_EQ((*load)["args"]["brick"].kind, Json::Kind::kNumber);
    EXPECT_EQ((*counters.back())["args"].object.size(), 2u);
    EXPECT_TRUE((*counters.back())["args"].Has("resident_bytes"));
}

TEST_F(TraceTest, EnclosingSpanIsWrittenBeforeTheSpansItContains) {
    TraceRecorder trace;
    {
        TraceSpan outer(&trace, "outer", "test");
        TraceSpan inner(&trace, "inner", "test");
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }  // inner ends (and is recorded) first
    std::vector<Json> events = WriteAndRead(trace);
    auto complete = OfPhase(events, "X");
    ASSERT_EQ(complete.size(), 2u);
    EXPECT_EQ((*complete[0])["name"].string, "outer");
    EXPECT_EQ((*complete[1])["name"].string, "inner");
    const Json& outer = *complete[0];
    const Json& inner = *complete[1];
    EXPECT_LE(outer["ts"].number, inner["ts"].number);
    EXPECT_GE(outer["ts"].number + outer["dur"].number, inner["ts"].number + inner["dur"].number);
    EXPECT_GE(inner["dur"].number, 1000.0) << "durations are in microseconds";
}

TEST_F(TraceTest, EndBeforeStartIsAZeroLengthSpan) {
    TraceRecorder trace;
    auto now = TraceRecorder::Clock::now();
    trace.Complete("backwards", "test", now, now - std::chrono::milliseconds(5));
    std::vector<Json> events = WriteAndRead(trace);
    auto complete = OfPhase(events, "X");
    ASSERT_EQ(complete.size(), 1u);
    EXPECT_EQ((*complete[0])["dur"].number, 0.0);
}

TEST_F(TraceTest, StringsAreEscaped) {
    const std::string nasty = "say \"hi\" C:\\bricks\\0\nnext line\ttab\x01\x1f end \xc3\xa9";
    TraceRecorder trace;
    trace.NameThread(nasty);
    trace.Instant(nasty, "cat\"egory", {{"key \"quoted\"", nasty}});
    std::vector<Json> events = WriteAndRead(trace);
    ASSERT_FALSE(events.empty());
    EXPECT_NE(text_.find(R"(say \"hi\" C:\\bricks\\0\nnext line\ttab\u0001\u001f end)"),
              std::string::npos)
        << text_;
    auto instants = OfPhase(events, "i");
    ASSERT_EQ(instants.size(), 1u);
    EXPECT_EQ((*instants[0])["name"].string, nasty);
    EXPECT_EQ((*instants[0])["cat"].string, "cat\"egory");
    EXPECT_EQ((*instants[0])["args"]["key \"quoted\""].string, nasty);
    bool named = false;
    for (const Json* m : OfPhase(events, "M")) {
        if ((*m)["name"].string == "thread_name") named = (*m)["args"]["name"].string == nasty;
    }
    EXPECT_TRUE(named);
}

TEST_F(TraceTest, NumbersThatJsonCannotHoldBecomeNull) {
    TraceRecorder trace;
    trace.Counter("values", {{"half", 0.5}, {"nan", std::nan("")}, {"big", int64_t{1} << 40}});
    std::vector<Json> events = WriteAndRead(trace);
    auto counters = OfPhase(events, "C");
    ASSERT_EQ(counters.size(), 1u);
    const Json& args = (*counters[0])["args"];
    EXPECT_EQ(args["half"].number, 0.5);
    EXPECT_EQ(args["nan"].kind, Json::Kind::kNull);
    EXPECT_EQ(args["big"].number, double(int64_t{1} << 40));
}

TEST_F(TraceTest, EventsBeyondTheLimitAreDroppedAndCounted) {
    TraceRecorder trace(/*max_events=*/10);
    for (int i = 0; i < 25; ++i) trace.Instant("tick", "test", {{"i", i}});
    trace.NameThread("still named");  // names are not events and are never dropped
    EXPECT_EQ(trace.event_count(), 10u);
    EXPECT_EQ(trace.dropped_events(), 15u);

    std::vector<Json> events = WriteAndRead(trace);
    size_t ticks = 0;
    int last_i = -1;
    for (const Json& e : events) {
        if (e["name"].string != "tick") continue;
        ++ticks;
        last_i = int(e["args"]["i"].number);
    }
    EXPECT_EQ(ticks, 10u);
    EXPECT_EQ(last_i, 9) << "the first events are kept, the later ones dropped";

    const Json* note = nullptr;
    const Json* marker = nullptr;
    bool named = false;
    for (const Json& e : events) {
        if (e["name"].string == "trace_dropped_events") note = &e;
        if (e["name"].string == "trace events dropped") marker = &e;
        if (e["name"].string == "thread_name") named = e["args"]["name"].string == "still named";
    }
    ASSERT_NE(note, nullptr);
    EXPECT_EQ((*note)["ph"].string, "M");
    EXPECT_EQ((*note)["args"]["dropped_events"].number, 15.0);
    EXPECT_EQ((*note)["args"]["max_events"].number, 10.0);
    ASSERT_NE(marker, nullptr);
    EXPECT_EQ((*marker)["ph"].string, "i");
    EXPECT_EQ((*marker)["s"].string, "g");
    EXPECT_TRUE(named);
}

TEST_F(TraceTest, WriteIntoMissingDirectoryNamesThePath) {
    TraceRecorder trace;
    trace.Instant("tick", "test");
    fs::path path = dir_ / "no such dir" / "trace.json";
    Status status = trace.Write(path);
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.code(), StatusCode::kIoError);
    EXPECT_NE(status.message().find(path.string()), std::string::npos) << status.message();
    EXPECT_FALSE(fs::exists(path));
}

TEST_F(TraceTest, NullRecorderMakesSpansNoOps) {
    TraceSpan span(nullptr, "nothing", "test");
    span.AddArg({"brick", 12});
    span.End();
    span.End();  // ending twice is allowed
    SUCCEED();
}

TEST_F(TraceTest, EndedSpanIsRecordedOnce) {
    TraceRecorder trace;
    {
        TraceSpan span(&trace, "early", "test");
        span.AddArg({"triangles", 1234});
        span.End();
        EXPECT_EQ(trace.event_count(), 1u);
    }
    EXPECT_EQ(trace.event_count(), 1u) << "the destructor must not record an ended span again";
    std::vector<Json> events = WriteAndRead(trace);
    auto complete = OfPhase(events, "X");
    ASSERT_EQ(complete.size(), 1u);
    EXPECT_EQ((*complete[0])["args"]["triangles"].number, 1234.0);
}

TEST_F(TraceTest, HundredThousandEventsAreCheap) {
    // Two threads, as on a small machine; the bound is loose (a shared machine), the printed cost
    // is the number to look at.
    constexpr int kPerThread = 50'000;
    TraceRecorder trace;
    auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> threads;
    for (int t = 0; t < 2; ++t) {
        threads.emplace_back([&trace] {
            for (int i = 0; i < kPerThread; ++i) {
                TraceSpan span(&trace, "trace rays", "integrator");
                span.AddArg({"rays", i});
            }
        });
    }
    for (auto& thread : threads) thread.join();
    double record_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    start = std::chrono::steady_clock::now();
    ASSERT_TRUE(trace.Write(dir_ / "big.json").ok());
    double write_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(trace.event_count(), size_t(2 * kPerThread));
    std::printf("100k spans: %.0f ns per span recorded, written in %.3f s (%.1f MB)\n",
                1e9 * record_s / (2 * kPerThread), write_s, fs::file_size(dir_ / "big.json") / 1e6);
    EXPECT_LT(record_s, 2.0);
    EXPECT_LT(write_s, 5.0);
}

}  // namespace
}  // namespace nave
