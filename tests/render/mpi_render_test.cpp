// `mpirun -np N nave render` as users run it (docs/distributed.md): 2 and 3 ranks, each holding its
// own bricks, give the single-process image bit for bit in path and photon mode (RGB; the abbey's
// textured glass included), and report the rays they sent each other, every one received; a
// corrupt brick ends the whole job naming the brick and the rank.
// Runs mpirun and the nave executable (NAVE_BINARY, MPIEXEC), from a process of its own that is not
// an MPI rank.

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/run_nave.h"
#include "store/store_reader.h"

namespace nave::render {
namespace {

namespace fs = std::filesystem;

// mpirun for this machine and CI containers: more ranks than cores, as root, and shared memory
// without cross-memory attach (ptrace), which containers forbid.
std::string Mpirun(int ranks) {
    // Under AddressSanitizer the ranks check no leaks: Open MPI's plugins are unloaded before the
    // check, and what they kept shows as frames of no module, which no suppression can name.
    return std::string(
               "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
               "OMPI_MCA_btl_vader_single_copy_mechanism=none "
               "ASAN_OPTIONS=detect_leaks=0:new_delete_type_mismatch=0 timeout 120 ") +
           MPIEXEC + " -np " + std::to_string(ranks) + " --oversubscribe ";
}

// The RGB channels of an EXR.
std::vector<float> Rgb(const fs::path& exr) {
    OIIO::ImageBuf image(exr.string());
    std::vector<float> rgb;
    if (!image.read(0, 0, true, OIIO::TypeDesc::FLOAT)) return rgb;
    const OIIO::ImageSpec& spec = image.spec();
    rgb.resize(size_t(spec.width) * spec.height * 3);
    image.get_pixels(OIIO::ROI(0, spec.width, 0, spec.height, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT,
                     rgb.data());
    return rgb;
}

class MpiRender : public ::testing::Test {
  protected:
    // One store for every test: the detail-1 abbey in 64 small bricks, rendered in path mode with
    // the abbey's config, path guiding included (the ranks share the guide's credits). Most tests
    // hold each rank's bricks in memory; RanksPageTheirBricksUnderTheirBudgets pages them.
    static void SetUpTestSuite() {
        dir_ = new fs::path(fs::temp_directory_path() / ("nave_mpi_" + std::to_string(getpid())));
        fs::create_directories(*dir_);
        const test::CommandResult made = test::RunNave(
            "preprocess --generate abbey:detail=1 --brick-triangles 40000 -q -o " + Store());
        ASSERT_EQ(made.exit_code, 0) << made.output;
    }
    static void TearDownTestSuite() {
        fs::remove_all(*dir_);
        delete dir_;
    }
    static std::string Store() { return (*dir_ / "abbey.nave").string(); }
    static std::string Config() { return std::string(NAVE_SOURCE_DIR) + "/configs/abbey.toml"; }
    static std::string Render(const std::string& out, const std::string& mode = "path") {
        return std::string(NAVE_BINARY) + " render " + Store() + " -c " + Config() + " --mode " +
               mode + " --resolution 96x64 --spp 4 -o " + (*dir_ / out).string();
    }
    static test::CommandResult Shell(const std::string& command) {
        // RunNave prefixes the binary: run the shell's own way instead.
        test::CommandResult result;
        FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
        if (pipe == nullptr) return result;
        char buffer[4096];
        size_t n;
        while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0)
            result.output.append(buffer, n);
        const int status = ::pclose(pipe);
        result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        return result;
    }
    static void ExpectRanksGiveTheSingleProcessImage(const std::string& mode,
                                                     const std::string& flags,
                                                     const std::string& progress,
                                                     std::vector<std::string>* outputs);
    /// Runs `render(out)`, a command that writes the image `out`, as one process and as 2 ranks
    /// (`stem`1.exr, `stem`2.exr), and expects the same RGB, bit for bit. Returns the one
    /// process's (empty if a run failed: the test has failed then).
    static std::vector<float> ExpectTwoRanksAsOneProcess(
        const std::function<std::string(const std::string&)>& render, const std::string& stem) {
        const test::CommandResult one = Shell(render(stem + "1.exr"));
        EXPECT_EQ(one.exit_code, 0) << one.output;
        const test::CommandResult two = Shell(Mpirun(2) + render(stem + "2.exr"));
        EXPECT_EQ(two.exit_code, 0) << two.output;
        if (one.exit_code != 0 || two.exit_code != 0) return {};
        std::vector<float> a = Rgb(*dir_ / (stem + "1.exr"));
        EXPECT_FALSE(a.empty()) << stem;
        EXPECT_EQ(a, Rgb(*dir_ / (stem + "2.exr"))) << stem;
        return a;
    }
    static fs::path* dir_;
};
fs::path* MpiRender::dir_ = nullptr;

// Renders `mode` (with `flags`) as one process and as 2 and 3 ranks, and expects of each run of
// ranks: the one process's image bit for bit (RGB), rank 0 alone writing it with the ranks'
// summary, rank 0 reading fewer than the store's 64 bricks (each rank reads only its own, for the
// render and for the scan of the model's portals), and rank 0's bar ending at `progress` (the
// whole job's). `outputs`: each run's output, for the mode's own checks.
void MpiRender::ExpectRanksGiveTheSingleProcessImage(const std::string& mode,
                                                     const std::string& flags,
                                                     const std::string& progress,
                                                     std::vector<std::string>* outputs) {
    const test::CommandResult one = Shell(Render(mode + "1.exr", mode) + flags);
    ASSERT_EQ(one.exit_code, 0) << one.output;
    const std::vector<float> reference = Rgb(*dir_ / (mode + "1.exr"));
    ASSERT_FALSE(reference.empty());
    for (int ranks : {2, 3}) {
        SCOPED_TRACE(::testing::Message() << ranks << " ranks");
        const std::string name = mode + "_ranks" + std::to_string(ranks) + ".exr";
        const test::CommandResult r = Shell(Mpirun(ranks) + Render(name, mode) + flags);
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_NE(r.output.find("ranks " + std::to_string(ranks) + ": "), std::string::npos)
            << r.output;
        EXPECT_NE(r.output.find("rays sent between them"), std::string::npos) << r.output;
        const size_t loads = r.output.find(", loads ");
        ASSERT_NE(loads, std::string::npos) << r.output;
        EXPECT_LT(std::atoi(r.output.c_str() + loads + 8), 64) << r.output;
        EXPECT_NE(r.output.find(progress), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("nave render: wrote", r.output.find("nave render: wrote") + 1),
                  std::string::npos)
            << "more than one rank wrote: " << r.output;
        const std::vector<float> image = Rgb(*dir_ / name);
        ASSERT_EQ(image.size(), reference.size());
        size_t differ = 0;
        for (size_t i = 0; i < image.size(); ++i) differ += image[i] != reference[i];
        EXPECT_EQ(differ, 0u) << "of " << image.size() << " values";
        outputs->push_back(r.output);
    }
}

TEST_F(MpiRender, RanksGiveTheSingleProcessImage) {
    // Paths end on every rank, and rank 0's bar counts them all: 96 x 64 x 4.
    std::vector<std::string> outputs;
    ExpectRanksGiveTheSingleProcessImage("path", "", "render 100.0% 24.6 k paths", &outputs);
    for (const std::string& output : outputs) {
        // After the complete drains of passes 1, 2 and 4 the ranks re-balance their bricks by the
        // time their batches took when the busiest took 1.2x the mean (timing decides how often):
        // the image stays the single process's.
        EXPECT_NE(output.find("bricks re-balanced "), std::string::npos) << output;
    }
}

// The rounds a render's summary reports: its samples per pixel ("after 62 samples per pixel",
// `unit` " samples per pixel") or iterations ("after 18 iterations, target", " iterations,"), or
// -1.
int RoundsReported(const std::string& output, const std::string& unit) {
    const size_t at = output.find(unit);
    if (at == std::string::npos) return -1;
    const size_t start = output.rfind(' ', at - 1);
    return std::atoi(output.substr(start + 1, at - start - 1).c_str());
}

// A noise target: the ranks estimate the whole image's noise together (each holds the part of the
// image it traced) and stop after the pass (photon mode: the iteration) one process stops after,
// with its image.
TEST_F(MpiRender, ANoiseTargetStopsTheRanksWhereOneProcessStops) {
    struct Case {
        std::string settings, unit, target;
        int most;
    };
    auto check = [&](const Case& c) {
        SCOPED_TRACE(c.settings);
        auto render = [&](const std::string& out) {
            return std::string(NAVE_BINARY) + " render " + Store() + " -c " + Config() +
                   c.settings + " --resolution 96x64 --noise " + c.target + " -o " +
                   (*dir_ / out).string();
        };
        const test::CommandResult one = Shell(render("noise1.exr"));
        ASSERT_EQ(one.exit_code, 0) << one.output;
        const test::CommandResult two = Shell(Mpirun(2) + render("noise2.exr"));
        ASSERT_EQ(two.exit_code, 0) << two.output;
        const int rounds = RoundsReported(one.output, c.unit);
        EXPECT_GT(rounds, 1) << one.output;
        EXPECT_LT(rounds, c.most) << "the target should end the render early: " << one.output;
        EXPECT_EQ(RoundsReported(two.output, c.unit), rounds) << two.output;
        EXPECT_NE(two.output.find("target " + c.target + " reached"), std::string::npos)
            << two.output;
        const std::vector<float> a = Rgb(*dir_ / "noise1.exr"), b = Rgb(*dir_ / "noise2.exr");
        ASSERT_FALSE(a.empty());
        EXPECT_EQ(a, b);
    };
    check({" --mode path --spp 128", " samples per pixel", "0.2", 128});
    check({" --mode photon --iterations 40 --photons 50000", " iterations,", "0.25", 40});
}

// A time limit: each rank's clock may pass it after a different pass, and the ranks stop together
// after the first pass where one of them has.
TEST_F(MpiRender, ATimeLimitEndsTheRanksTogether) {
    const auto start = std::chrono::steady_clock::now();
    const test::CommandResult r =
        Shell(Mpirun(2) + NAVE_BINARY + " render " + Store() + " -c " + Config() +
              " --mode path --resolution 96x64 --spp 100000 --time-limit 3 -o " +
              (*dir_ / "limited.exr").string());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const int samples = RoundsReported(r.output, " samples per pixel");
    EXPECT_GT(samples, 0) << r.output;
    EXPECT_LT(samples, 100000) << r.output;
    EXPECT_LT(seconds, 60) << r.output;
    EXPECT_NE(r.output.find("ranks 2: "), std::string::npos) << r.output;
    EXPECT_FALSE(Rgb(*dir_ / "limited.exr").empty());
}

// Checkpoints: rank 0 writes one checkpoint holding every rank's samples and the path guide's
// credits together (photon mode: the density sums, once), which any number of processes
// continues: 2 ranks stop part way, and 3 ranks or one process finish with the image one process
// renders with checkpoints, bit for bit.
TEST_F(MpiRender, RanksWriteACheckpointThatAnyNumberOfProcessesContinues) {
    struct Case {
        std::string mode, rounds, stop_after;
    };
    auto check = [&](const Case& c) {
        SCOPED_TRACE(c.mode);
        const std::string settings = " --mode " + c.mode + " " + c.rounds;
        auto render = [&](const std::string& out, const std::string& flags) {
            return std::string(NAVE_BINARY) + " render " + Store() + " -c " + Config() + settings +
                   " --resolution 96x64 -q -o " + (*dir_ / (c.mode + out)).string() + " " + flags;
        };
        const std::string one_ckpt = (*dir_ / (c.mode + "_one.ckpt")).string();
        const test::CommandResult one = Shell(render("ckpt1.exr", "--checkpoint " + one_ckpt));
        ASSERT_EQ(one.exit_code, 0) << one.output;
        const std::vector<float> reference = Rgb(*dir_ / (c.mode + "ckpt1.exr"));
        ASSERT_FALSE(reference.empty());

        const fs::path ranks_ckpt = *dir_ / (c.mode + "_ranks.ckpt");
        const test::CommandResult first =
            Shell(Mpirun(2) + render("ckpt2.exr", "--checkpoint " + ranks_ckpt.string() +
                                                      " --stop-after " + c.stop_after));
        ASSERT_EQ(first.exit_code, 0) << first.output;
        ASSERT_TRUE(fs::exists(ranks_ckpt));
        const fs::path copy = *dir_ / (c.mode + "_copy.ckpt");
        fs::copy_file(ranks_ckpt, copy, fs::copy_options::overwrite_existing);

        const test::CommandResult three =
            Shell(Mpirun(3) + render("ckpt3.exr", "--resume " + ranks_ckpt.string()));
        ASSERT_EQ(three.exit_code, 0) << three.output;
        EXPECT_EQ(Rgb(*dir_ / (c.mode + "ckpt3.exr")), reference);
        const test::CommandResult single = Shell(render("ckpt4.exr", "--resume " + copy.string()));
        ASSERT_EQ(single.exit_code, 0) << single.output;
        EXPECT_EQ(Rgb(*dir_ / (c.mode + "ckpt4.exr")), reference);
    };
    check({"path", "--spp 8", "3"});
    check({"photon", "--iterations 4 --photons 60000", "2"});
}

// --trace: each rank writes its own trace beside the path asked for, as a process of its own (its
// rank), so that the files merge into one view.
TEST_F(MpiRender, EachRankWritesItsOwnTrace) {
    const fs::path trace = *dir_ / "render.json";
    const test::CommandResult r =
        Shell(Mpirun(2) + Render("traced.exr") + " --trace " + trace.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_FALSE(fs::exists(trace));
    for (int rank : {0, 1}) {
        SCOPED_TRACE(::testing::Message() << "rank " << rank);
        std::ifstream in(*dir_ / ("render.rank" + std::to_string(rank) + ".json"));
        ASSERT_TRUE(in.good());
        const std::string text((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
        EXPECT_NE(text.find("\"pid\":" + std::to_string(rank) + ","), std::string::npos);
        EXPECT_NE(text.find("nave rank " + std::to_string(rank) + " of 2 on "), std::string::npos);
        EXPECT_NE(text.find("\"batch\""), std::string::npos) << "no batches traced";
    }
}

// Each rank pages its own bricks under its own --memory, 2 and 3 ranks, in path and photon mode:
// the job completes with every ray and photon exchanged, and its image is the one process's in-core
// image bit for bit (the budget changes only which bricks are resident when, never a ray's
// numbers).
TEST_F(MpiRender, RanksPageTheirBricksUnderTheirBudgets) {
    // The smallest --memory a rank of this build can render with (MPI and sanitizers make the
    // process larger), from the refusal of a budget far too small, and 64 MiB more (the reserve
    // for the ray queues grows with --memory, the rest goes to bricks): a rank's 32 bricks take
    // 68 MiB.
    const test::CommandResult refused = Shell(Mpirun(2) + Render("probe.exr") + " --memory 1M");
    ASSERT_NE(refused.exit_code, 0) << refused.output;
    const size_t needed = refused.output.find(" bytes) is needed");
    ASSERT_NE(needed, std::string::npos) << refused.output;
    const size_t number = refused.output.rfind('(', needed);
    ASSERT_NE(number, std::string::npos) << refused.output;
    const uint64_t minimum = std::strtoull(refused.output.c_str() + number + 1, nullptr, 10);
    ASSERT_GT(minimum, 0u) << refused.output;
    for (const std::string mode : {"path", "photon"}) {
        SCOPED_TRACE(mode);
        const std::string settings = " --iterations 2 --photons 60000";
        const std::string in_core = "in_core_" + mode + ".exr";
        const test::CommandResult one = Shell(Render(in_core, mode) + settings);
        ASSERT_EQ(one.exit_code, 0) << one.output;
        const std::vector<float> reference = Rgb(*dir_ / in_core);
        ASSERT_FALSE(reference.empty());
        // 3 ranks hold about 21 bricks each (45 MiB): a smaller margin keeps them evicting (the
        // reserve grows with --memory, so not much smaller).
        for (const auto& [ranks, margin] : {std::pair{2, 64}, std::pair{3, 40}}) {
            SCOPED_TRACE(::testing::Message() << ranks << " ranks");
            const std::string memory = std::to_string((minimum >> 20) + margin) + "M";
            const std::string name = "paged_" + mode + std::to_string(ranks) + ".exr";
            std::string paged = Mpirun(ranks) + Render(name, mode);
            paged += settings;
            paged += " --memory " + memory;
            const test::CommandResult r = Shell(paged);
            ASSERT_EQ(r.exit_code, 0) << r.output;
            EXPECT_NE(r.output.find("rays sent between them"), std::string::npos) << r.output;
            const size_t evictions = r.output.find("evictions ");
            ASSERT_NE(evictions, std::string::npos) << r.output;
            EXPECT_NE(r.output.compare(evictions, 11, "evictions 0"), 0) << r.output;
            EXPECT_EQ(Rgb(*dir_ / name), reference);
        }
    }
}

// Levels of detail are slots of their bricks: they go to the brick's rank.
// The rays sent between the ranks, from the summary's "ranks 2: 1.2 k rays sent between them";
// -1 if absent.
double RaysSentBetweenRanks(const std::string& output) {
    const size_t at = output.find(" rays sent between them");
    if (at == std::string::npos) return -1;
    const size_t start = output.rfind(": ", at);
    if (start == std::string::npos) return -1;
    const std::string number = output.substr(start + 2, at - start - 2);  // "630", "1.2 k"
    const double scale = number.ends_with(" k") ? 1e3 : number.ends_with(" M") ? 1e6 : 1;
    return std::atof(number.c_str()) * scale;
}

// With levels of detail every rank holds the coarse levels its pager keeps and traces the rays
// that meet them where they are (--coarse-levels-everywhere, on by default): fewer rays travel
// between the ranks, and the image is the single process's, in path and photon mode (whose
// photons go to the brick's owner, where the visible points they reach are), on or off, and
// after re-balancing has the busier rank hand rays entering the coarse levels to the other.
TEST_F(MpiRender, CoarseLevelsOnEveryRankKeepRaysHomeAndTheImage) {
    const std::string store = (*dir_ / "levels.nave").string();
    const test::CommandResult made = test::RunNave(
        "preprocess --generate abbey:detail=1 --brick-triangles 40000 --levels -q -o " + store);
    ASSERT_EQ(made.exit_code, 0) << made.output;
    for (const std::string mode : {"path", "photon"}) {
        SCOPED_TRACE(mode);
        // 8 passes: the ranks re-balance at passes 2 and 4 (path guiding's rounds) when one does
        // 1.2x the mean, and then hand rays entering the coarse levels to each other (as many as
        // the measured imbalance says: the rays sent are then counted in 2 passes, before it).
        auto render = [&](const std::string& out, const std::string& flags, int spp = 8) {
            std::string command = std::string(NAVE_BINARY) + " render " + store;
            command += " -c " + Config() + " --mode " + mode + " --spp " + std::to_string(spp);
            command += " --lod auto --resolution 64x48 --iterations 2 --photons 50000 -o ";
            command += (*dir_ / out).string() + flags;
            return command;
        };
        const test::CommandResult one = Shell(render(mode + "_one.exr", " -q"));
        ASSERT_EQ(one.exit_code, 0) << one.output;
        const std::vector<float> reference = Rgb(*dir_ / (mode + "_one.exr"));
        ASSERT_FALSE(reference.empty());
        double sent[2] = {-1, -1};
        for (const bool everywhere : {true, false}) {
            const std::string out = mode + (everywhere ? "_everywhere.exr" : "_owner.exr");
            const std::string flags = everywhere ? "" : " --coarse-levels-everywhere off";
            const test::CommandResult two = Shell(Mpirun(2) + render(out, flags));
            ASSERT_EQ(two.exit_code, 0) << two.output;
            EXPECT_EQ(Rgb(*dir_ / out), reference) << out;
            const test::CommandResult counted =
                mode == "photon" ? two : Shell(Mpirun(2) + render("counted.exr", flags, 2));
            ASSERT_EQ(counted.exit_code, 0) << counted.output;
            sent[everywhere] = RaysSentBetweenRanks(counted.output);
            EXPECT_GT(sent[everywhere], 0) << counted.output;
        }
        EXPECT_LT(sent[true], sent[false]);
    }
}

// Drifting dust cut into the bricks by preprocess (grid = "store"): each brick's piece comes with
// the brick, on the rank that owns it, and a path's flight carries its depth from brick to brick
// and rank to rank. Paged under a budget (pieces evicted and read again with their bricks) and as
// 2 ranks, the image of one process in core, bit for bit.
TEST_F(MpiRender, AGridStoredInTheBricksGivesTheSingleProcessImage) {
    const fs::path dust = *dir_ / "dust.vdb", store = *dir_ / "dusty.nave";
    ASSERT_EQ(test::RunNave("generate dust -o " + dust.string()).exit_code, 0);
    const test::CommandResult made =
        test::RunNave("preprocess --generate abbey:detail=1 --brick-triangles 40000 -q " +
                      dust.string() + " -o " + store.string());
    ASSERT_EQ(made.exit_code, 0) << made.output;
    {
        std::ifstream in(std::string(NAVE_SOURCE_DIR) + "/configs/abbey_dust.toml");
        std::stringstream text;
        text << in.rdbuf();
        std::string config = text.str();
        const size_t at = config.find("grid = \"dust.vdb\"");
        ASSERT_NE(at, std::string::npos);
        config.replace(at, std::string("grid = \"dust.vdb\"").size(), "grid = \"store\"");
        std::ofstream(*dir_ / "dusty.toml") << config;
    }
    auto render = [&](const std::string& out, const std::string& flags = "") {
        return std::string(NAVE_BINARY) + " render " + store.string() + " -c " +
               (*dir_ / "dusty.toml").string() + " --resolution 64x48 --spp 2 " + flags + " -o " +
               (*dir_ / out).string();
    };
    const std::vector<float> a = ExpectTwoRanksAsOneProcess(
        [&](const std::string& out) { return render(out, "-q"); }, "dust");
    ASSERT_FALSE(a.empty());
    const test::CommandResult paged = Shell(render("dust_paged.exr", "--memory 300M"));
    ASSERT_EQ(paged.exit_code, 0) << paged.output;
    EXPECT_NE(paged.output.find("evictions"), std::string::npos) << paged.output;
    EXPECT_EQ(a, Rgb(*dir_ / "dust_paged.exr"));
}

// The abbey in haze (a medium over the church): a path's or a photon's scattering in the air
// happens on the rank whose brick its free flight ends in, and its rays go on as any other. One
// process's image, bit for bit, in both modes.
TEST_F(MpiRender, AMediumGivesTheSingleProcessImage) {
    for (const std::string mode : {"path", "photon"}) {
        auto render = [&](const std::string& out) {
            return std::string(NAVE_BINARY) + " render " + Store() + " -c " + NAVE_SOURCE_DIR +
                   "/configs/abbey_haze.toml --mode " + mode +
                   " --resolution 64x48 --spp 2 --iterations 2 --photons 20000 -q -o " +
                   (*dir_ / out).string();
        };
        ExpectTwoRanksAsOneProcess(render, "haze_" + mode);
    }
}

// Photon mode: each rank makes the visible points of its own bricks and sends each to the ranks
// owning another brick its gather sphere reaches; photons travel between the ranks as rays do, and
// what they teach (the sun's photon guide, the windows, the gather guide) is summed in integers, so
// every rank learns what one process learns; the photons' flux is summed in doubles. The image is
// one process's, bit for bit (RGB). The abbey's config is photon mode with final gathering, portals
// and sky windows: all of it is exercised.
TEST_F(MpiRender, RanksGiveTheSingleProcessImageInPhotonMode) {
    // Iterations are the job's: rank 0's bar counts each once.
    std::vector<std::string> outputs;
    ExpectRanksGiveTheSingleProcessImage("photon", " --iterations 3 --photons 100000",
                                         "photon mapping 100.0% 3 iterations", &outputs);
    EXPECT_EQ(outputs.size(), 2u);
}

TEST_F(MpiRender, ACorruptBrickEndsTheJobNamingTheBrickAndTheRank) {
    const fs::path damaged = *dir_ / "damaged.nave";
    fs::copy_file(Store(), damaged, fs::copy_options::overwrite_existing);
    fs::copy(Store() + ".textures", damaged.string() + ".textures",
             fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    {
        auto store = store::Store::Open(damaged);
        ASSERT_TRUE(store.ok()) << store.status().ToString();
        const store::BrickInfo& brick = (*store)->bricks()[5];
        std::fstream file(damaged, std::ios::in | std::ios::out | std::ios::binary);
        file.seekp(std::streamoff(brick.mesh.offset + brick.mesh.length / 2));
        file.put('\x5a');
    }
    const std::string command = std::string(NAVE_BINARY) + " render " + damaged.string() + " -c " +
                                Config() + " --mode path --resolution 32x24 --spp 1 -o " +
                                (*dir_ / "damaged.exr").string();
    const auto start = std::chrono::steady_clock::now();
    const test::CommandResult r = Shell(Mpirun(2) + command);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("brick 5"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("checksum"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("on rank "), std::string::npos) << r.output;
    EXPECT_LT(seconds, 60) << "the job did not end soon after the error";
    EXPECT_FALSE(fs::exists(*dir_ / "damaged.exr"));
}

// The pids of `pid`'s children (Linux: /proc/PID/task/PID/children).
std::vector<pid_t> Children(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
    std::vector<pid_t> children;
    pid_t child;
    while (in >> child) children.push_back(child);
    return children;
}

// A job started in the background: mpirun's pid and its two ranks', once both run.
struct BackgroundJob {
    pid_t mpirun = -1;
    std::vector<pid_t> ranks;
};
BackgroundJob StartJob(const std::string& command) {
    BackgroundJob job;
    job.mpirun = ::fork();
    if (job.mpirun == 0) {
        ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    if (job.mpirun < 0) return job;
    // `timeout` runs mpirun, which runs the ranks: wait for both ranks to be rendering. Up to a
    // minute: on a machine that has just installed Open MPI and runs other tests beside this one,
    // its first start took over 10 s (a fresh Debian 12).
    for (int i = 0; i < 1200 && job.ranks.size() < 2; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        job.ranks.clear();
        for (pid_t launcher : Children(job.mpirun))
            for (pid_t rank : Children(launcher)) job.ranks.push_back(rank);
    }
    if (job.ranks.size() < 2) {
        // The test fails on it; the job must not outlive it.
        ::kill(job.mpirun, SIGKILL);
        ::waitpid(job.mpirun, nullptr, 0);
    }
    return job;
}

std::string ReadAll(const fs::path& path) {
    std::ifstream in(path);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// How a job ended after its rank 1 got `signal`: mpirun's exit, the seconds it took from the
// signal, and what the job printed to `log`.
struct EndedJob {
    bool failed = false;  // killed, or a non-zero exit
    double seconds = 0;
    std::string output;
};
EndedJob SignalRankAndWait(const BackgroundJob& job, int signal, const fs::path& log) {
    EndedJob ended;
    const auto start = std::chrono::steady_clock::now();
    ::kill(job.ranks[1], signal);
    int status = 0;
    EXPECT_EQ(::waitpid(job.mpirun, &status, 0), job.mpirun);
    ended.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (signal == SIGSTOP) ::kill(job.ranks[1], SIGKILL);  // if mpirun left it stopped
    ended.failed = !WIFEXITED(status) || WEXITSTATUS(status) != 0;
    ended.output = ReadAll(log);
    return ended;
}

// A rank killed outright mid-render (out of memory, an operator's kill -9): mpirun ends the whole
// job, naming the rank and the signal, and no image is written.
TEST_F(MpiRender, ARankKilledMidRenderEndsTheJob) {
    const fs::path log = *dir_ / "killed.log";
    // In-core, and long enough (256 samples) to be killed mid-render.
    const BackgroundJob job =
        StartJob("exec env " + Mpirun(2) + NAVE_BINARY + " render " + Store() + " -c " + Config() +
                 " --mode path --resolution 96x64 --spp 256 -o " + (*dir_ / "killed.exr").string() +
                 " > " + log.string() + " 2>&1");
    ASSERT_GE(job.mpirun, 0);
    ASSERT_EQ(job.ranks.size(), 2u) << "the ranks did not start";
    std::this_thread::sleep_for(std::chrono::seconds(2));
    const EndedJob ended = SignalRankAndWait(job, SIGKILL, log);
    EXPECT_TRUE(ended.failed) << ended.output;
    EXPECT_NE(ended.output.find("signal 9"), std::string::npos) << ended.output;
    EXPECT_LT(ended.seconds, 30) << "the job did not end soon after the rank was killed";
    EXPECT_FALSE(fs::exists(*dir_ / "killed.exr"));
}

// A rank that stops without dying (SIGSTOP standing for a hung rank): the others wait for it
// --rank-timeout at most, then end the job naming the wait; no image, never a hang.
TEST_F(MpiRender, AHungRankEndsTheJobAfterTheRankTimeout) {
    const fs::path log = *dir_ / "hung.log";
    const BackgroundJob job =
        StartJob("exec env " + Mpirun(2) + NAVE_BINARY + " render " + Store() + " -c " + Config() +
                 " --mode path --resolution 96x64 --spp 256 --rank-timeout 3s -o " +
                 (*dir_ / "hung.exr").string() + " > " + log.string() + " 2>&1");
    ASSERT_GE(job.mpirun, 0);
    ASSERT_EQ(job.ranks.size(), 2u) << "the ranks did not start";
    // Once rank 0's bar shows the render going (past start-up and the model scan, slow under the
    // sanitizers).
    for (int i = 0; i < 600 && ReadAll(log).find("info: render ") == std::string::npos; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const EndedJob ended = SignalRankAndWait(job, SIGSTOP, log);
    EXPECT_TRUE(ended.failed) << ended.output;
    // The stopped process is rank 0 or 1 (mpirun's children are not listed in rank order): the
    // other one names the wait.
    EXPECT_TRUE(ended.output.find("error on rank 0 of 2") != std::string::npos ||
                ended.output.find("error on rank 1 of 2") != std::string::npos)
        << ended.output;
    EXPECT_NE(ended.output.find("has stopped or hangs"), std::string::npos) << ended.output;
    EXPECT_LT(ended.seconds, 60) << "the job did not end after the rank timeout";
    EXPECT_FALSE(fs::exists(*dir_ / "hung.exr"));
}

}  // namespace
}  // namespace nave::render
