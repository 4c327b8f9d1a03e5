// End-to-end: `nave render --checkpoint / --resume / --stop-after / --checkpoint-every` as users
// type them, on small built-in scenes: the resumed image is the uninterrupted one (bit for bit on
// one thread with the fullest brick always first: prefer_resident above 1), and every
// checkpoint that does not belong to the render, or is damaged, is refused with a message saying
// why.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/run_nave.h"
#include "src/core/file.h"
#include "src/render/film/checkpoint.h"

namespace nave::render {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::RunNave;

const std::string kConfigs = std::string(NAVE_TEST_FIXTURES) + "/../../configs/";

class CliResumeTest : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("nave_cli_resume_" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    std::string Path(const std::string& name) const { return (dir_ / name).string(); }
    /// A small path-mode render of the clutter scene; `extra` adds options.
    CommandResult Clutter(const std::string& extra, const std::string& out = "out.exr",
                          const std::string& resolution = "32x24", int spp = 6) const {
        return RunNave("render --procedural clutter:bricks=2 --config " + kConfigs +
                       "test_clutter.toml --resolution " + resolution + " --spp " +
                       std::to_string(spp) + " --threads 1 --pager prefer_resident=2 -o " +
                       Path(out) + " " + extra);
    }
    /// Expects `r` to have failed with exit code `code`, saying each of `says`.
    static void ExpectRefused(const CommandResult& r, int code,
                              std::initializer_list<std::string> says) {
        EXPECT_EQ(r.exit_code, code) << r.output;
        for (const std::string& s : says)
            EXPECT_NE(r.output.find(s), std::string::npos) << "expected \"" << s << "\" in\n"
                                                           << r.output;
    }

    std::filesystem::path dir_;
};

TEST_F(CliResumeTest, StoppedAndResumedEqualsOneRunInBothModes) {
    for (const std::string mode : {"path", "photon"}) {
        const std::string scene =
            mode == "path"
                ? "--procedural clutter:bricks=2 --config " + kConfigs + "test_clutter.toml --spp 6"
                : "--procedural caustic --config " + kConfigs +
                      "test_caustic.toml --iterations 5 --photons 20000";
        const std::string render =
            "render " + scene +
            " --resolution 32x24 --threads 1 --pager prefer_resident=2 --checkpoint-every 0 ";
        const CommandResult whole =
            RunNave(render + "--checkpoint " + Path("whole.ckpt") + " -o " + Path("whole.exr"));
        ASSERT_EQ(whole.exit_code, 0) << whole.output;
        const CommandResult part = RunNave(render + "--checkpoint " + Path("part.ckpt") +
                                           " --stop-after 2 -o " + Path("part.exr"));
        ASSERT_EQ(part.exit_code, 0) << part.output;
        const CommandResult rest =
            RunNave(render + "--resume " + Path("part.ckpt") + " -o " + Path("rest.exr"));
        ASSERT_EQ(rest.exit_code, 0) << rest.output;
        EXPECT_NE(rest.output.find("resuming from " + Path("part.ckpt") + " after 2"),
                  std::string::npos)
            << rest.output;
        // The film's sums, bit for bit: the last checkpoint of each holds them.
        auto a = ReadCheckpoint(Path("whole.ckpt"));
        auto b = ReadCheckpoint(Path("part.ckpt"));
        ASSERT_TRUE(a.ok() && b.ok());
        EXPECT_EQ(a->done, b->done) << mode;
        EXPECT_TRUE(a->sections == b->sections) << mode << ": the resumed render's state differs";
        const CommandResult same =
            RunNave("compare " + Path("whole.exr") + " " + Path("rest.exr") + " --identical");
        EXPECT_EQ(same.exit_code, 0) << mode << ": " << same.output;
        const CommandResult differ =
            RunNave("compare " + Path("whole.exr") + " " + Path("part.exr") + " --identical");
        EXPECT_NE(differ.exit_code, 0) << mode << ": " << differ.output;
    }
}

TEST_F(CliResumeTest, ACheckpointOfAnotherRenderIsRefusedSayingWhichDiffers) {
    ASSERT_EQ(Clutter("--checkpoint " + Path("c.ckpt") + " --stop-after 1").exit_code, 0);
    const std::string resume = " --resume " + Path("c.ckpt");
    ExpectRefused(RunNave("render --procedural furnace --config " + kConfigs +
                          "test_clutter.toml --resolution 32x24 -o " + Path("o.exr") + resume),
                  2, {"another model", "procedural furnace", "procedural clutter:bricks=2"});
    ExpectRefused(Clutter("--seed 5" + resume), 2, {"another config", "--seed"});
    ExpectRefused(Clutter(resume, "out.exr", "16x12"), 2, {"another config"});
    ExpectRefused(Clutter("--mode photon" + resume), 2,
                  {"written in path mode, this render is in photon mode"});
    // More passes than the first run asked for is fine: they only say when to stop.
    const CommandResult more = Clutter(resume, "out.exr", "32x24", 8);
    EXPECT_EQ(more.exit_code, 0) << more.output;

    // Another nave version: the same checkpoint, rewritten as if by 0.0.1.
    auto c = ReadCheckpoint(Path("c.ckpt"));
    ASSERT_TRUE(c.ok());
    c->identity.version = "0.0.1";
    ASSERT_TRUE(WriteCheckpoint(Path("old.ckpt"), *c).ok());
    ExpectRefused(Clutter("--resume " + Path("old.ckpt")), 2,
                  {"written by nave 0.0.1, this is nave " NAVE_VERSION});
}

TEST_F(CliResumeTest, DamagedCheckpointsAreRefused) {
    ASSERT_EQ(Clutter("--checkpoint " + Path("c.ckpt") + " --stop-after 1").exit_code, 0);
    auto bytes = ReadFileToString(Path("c.ckpt"));
    ASSERT_TRUE(bytes.ok());
    std::ofstream(Path("short.ckpt"), std::ios::binary) << bytes->substr(0, bytes->size() / 3);
    std::string flipped = *bytes;
    flipped[flipped.size() / 2] ^= 0x40;
    std::ofstream(Path("flipped.ckpt"), std::ios::binary) << flipped;
    std::ofstream(Path("text.ckpt")) << "not a checkpoint at all, but long enough to have a header";
    ExpectRefused(Clutter("--resume " + Path("short.ckpt"), "refused.exr"), 1,
                  {Path("short.ckpt"), "truncated"});
    ExpectRefused(Clutter("--resume " + Path("flipped.ckpt"), "refused.exr"), 1,
                  {Path("flipped.ckpt"), "checksum", "corrupt"});
    ExpectRefused(Clutter("--resume " + Path("text.ckpt"), "refused.exr"), 1,
                  {"not a nave checkpoint"});
    ExpectRefused(Clutter("--resume " + Path("none.ckpt"), "refused.exr"), 1,
                  {Path("none.ckpt"), "no such file"});
    EXPECT_FALSE(std::filesystem::exists(Path("refused.exr")));
}

TEST_F(CliResumeTest, CheckpointEveryParsingErrors) {
    for (const char* bad : {"10x", "ten", "-5m", "5 m", "m", "1e999"}) {
        ExpectRefused(Clutter(std::string("--checkpoint ") + Path("c.ckpt") +
                              " --checkpoint-every='" + bad + "'"),
                      2, {std::string("--checkpoint-every ") + bad, "90s, 10m, 1.5h or 2d"});
    }
    ExpectRefused(Clutter("--checkpoint-every 10m"), 2,
                  {"--checkpoint-every 10m needs --checkpoint FILE"});
    ExpectRefused(Clutter("--checkpoint " + dir_.string()), 2, {"is a directory"});
    EXPECT_FALSE(std::filesystem::exists(Path("c.ckpt")));
    for (const char* good : {"0", "90s", "1.5h", "2d", "45"}) {
        const CommandResult r =
            Clutter(std::string("--checkpoint ") + Path("c.ckpt") + " --checkpoint-every " + good);
        EXPECT_EQ(r.exit_code, 0) << good << ": " << r.output;
    }
    // The render writes a checkpoint after its last pass whatever the interval.
    auto c = ReadCheckpoint(Path("c.ckpt"));
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    EXPECT_EQ(c->done, 6u);
}

TEST_F(CliResumeTest, SigintFinishesThePassWritesTheCheckpointAndNoImage) {
    // Signalled once its first checkpoint exists (so its handlers are in place), a render of far
    // more passes than it will get through stops at the end of its pass.
    const std::string ckpt = Path("sig.ckpt");
    const std::string script =
        std::string(NAVE_BINARY) + " render --procedural clutter:bricks=2 --config " + kConfigs +
        "test_clutter.toml --resolution 32x24 --spp 100000 --threads 1 --checkpoint-every 0 "
        "--checkpoint " +
        ckpt + " -o " + Path("sig.exr") + " > " + Path("sig.log") +
        " 2>&1 & pid=$!; while [ ! -e " + ckpt +
        " ]; do sleep 0.05; done; kill -INT $pid; "
        "wait $pid; echo $?";
    FILE* pipe = ::popen(("sh -c '" + script + "'").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    char buffer[64] = {};
    const size_t n = std::fread(buffer, 1, sizeof(buffer) - 1, pipe);
    ::pclose(pipe);
    const std::string exit_code(buffer, n);
    auto log = ReadFileToString(Path("sig.log"));
    ASSERT_TRUE(log.ok());
    EXPECT_EQ(exit_code, "130\n") << *log;
    EXPECT_NE(log->find("interrupted after"), std::string::npos) << *log;
    EXPECT_NE(log->find("--resume " + ckpt), std::string::npos) << *log;
    EXPECT_FALSE(std::filesystem::exists(Path("sig.exr")));
    auto c = ReadCheckpoint(ckpt);
    ASSERT_TRUE(c.ok()) << c.status().ToString();
    EXPECT_GE(c->done, 1u);
    EXPECT_LT(c->done, 100000u);
}

TEST_F(CliResumeTest, StaleTemporariesOfKilledRendersAreRemovedAndSaid) {
    // A pid that is surely gone: a child that has exited and been reaped.
    const pid_t child = ::fork();
    if (child == 0) ::_exit(0);
    ASSERT_GT(child, 0);
    int status = 0;
    ::waitpid(child, &status, 0);
    const std::string dead = std::to_string(child);
    const std::string alive = std::to_string(::getpid());
    for (const std::string& name : {"out.exr.tmp-" + dead + "-0", "out.png.tmp-" + dead + "-1",
                                    "c.ckpt.tmp-" + dead + "-3", "out.exr.tmp-" + alive + "-0",
                                    "other.exr.tmp-" + dead + "-0", "out.exr.tmp-" + dead + "-x"}) {
        std::ofstream(Path(name)) << "partial";
    }
    const CommandResult r = Clutter("--checkpoint " + Path("c.ckpt"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const std::string& gone : {"out.exr.tmp-" + dead + "-0", "out.png.tmp-" + dead + "-1",
                                    "c.ckpt.tmp-" + dead + "-3"}) {
        EXPECT_FALSE(std::filesystem::exists(Path(gone))) << gone;
        EXPECT_NE(r.output.find("removed " + Path(gone) + ", left by an earlier nave run"),
                  std::string::npos)
            << r.output;
    }
    // A live process's, another output's, and a name that is not nave's own stay.
    for (const std::string& kept : {"out.exr.tmp-" + alive + "-0", "other.exr.tmp-" + dead + "-0",
                                    "out.exr.tmp-" + dead + "-x"}) {
        EXPECT_TRUE(std::filesystem::exists(Path(kept))) << kept;
    }
}

}  // namespace
}  // namespace nave::render
