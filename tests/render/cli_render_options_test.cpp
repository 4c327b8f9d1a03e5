// End-to-end: `nave render` command-line overrides, on the smallest built-in scene.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "common/run_nave.h"

namespace nave::render {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::RunNave;

const std::string kFurnaceConfig =
    std::string(NAVE_TEST_FIXTURES) + "/../../configs/test_furnace.toml";

TEST(CliRenderOptionsTest, ResolutionOverridesTheConfig) {
    const auto out = std::filesystem::temp_directory_path() /
                     ("nave_resolution_" + std::to_string(getpid()) + ".exr");
    const CommandResult r = RunNave("render --procedural furnace --config " + kFurnaceConfig +
                                    " --resolution 8x6 --spp 1 --threads 1 -o " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("8x6"), std::string::npos) << r.output;
    EXPECT_TRUE(std::filesystem::exists(out));
    std::filesystem::remove(out);
    std::filesystem::remove(std::filesystem::path(out).replace_extension(".png"));
}

TEST(CliRenderOptionsTest, MalformedResolutionIsAUsageErrorNamingIt) {
    for (const char* bad : {"12x", "0x10", "axb", "10x10x", "99999x2"}) {
        const CommandResult r =
            RunNave(std::string("render --procedural furnace --config ") + kFurnaceConfig +
                    " --resolution " + bad + " -o /tmp/never_written.exr");
        EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
        EXPECT_NE(r.output.find(std::string("--resolution ") + bad), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("WIDTHxHEIGHT"), std::string::npos) << r.output;
    }
    EXPECT_FALSE(std::filesystem::exists("/tmp/never_written.exr"));
}

// Global flags work after the subcommand too, as users type them; unknown ones are still refused.
TEST(CliRenderOptionsTest, GlobalFlagsAfterTheSubcommand) {
    const auto out = std::filesystem::temp_directory_path() /
                     ("nave_quiet_" + std::to_string(getpid()) + ".exr");
    const std::string render = "render --procedural furnace --config " + kFurnaceConfig +
                               " --resolution 8x6 --spp 1 --threads 1 -o " + out.string();
    const CommandResult loud = RunNave(render);
    ASSERT_EQ(loud.exit_code, 0) << loud.output;
    EXPECT_FALSE(loud.output.empty());
    const CommandResult quiet = RunNave(render + " -q");
    ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
    EXPECT_TRUE(quiet.output.empty()) << quiet.output;
    const CommandResult bogus = RunNave(render + " --bogus");
    EXPECT_NE(bogus.exit_code, 0);
    EXPECT_NE(bogus.output.find("--bogus"), std::string::npos) << bogus.output;
    std::filesystem::remove(out);
    std::filesystem::remove(std::filesystem::path(out).replace_extension(".png"));
}

}  // namespace
}  // namespace nave::render
