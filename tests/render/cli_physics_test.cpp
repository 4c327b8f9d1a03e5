// End-to-end: the `nave sun` and `nave spectrum` commands, run as the user would (NAVE_BINARY).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/run_nave.h"

namespace nave {
namespace {

using ::nave::test::CommandResult;
using ::nave::test::RunNave;

// The SPA paper's example (Reda & Andreas 2004, Table A5.1): zenith 50.11162°, azimuth 194.34024°.
TEST(CliSunTest, ReferenceExampleEndToEnd) {
    CommandResult r = RunNave(
        "sun --lat 39.742476 --lon -105.1786 --time 2003-10-17T12:30:30-07:00 --elevation 1830.14 "
        "--pressure 820 --temperature 11 --delta-t 67 --json");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("\"azimuth_deg\": 194.340"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"zenith_deg\": 50.111"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"cct_kelvin\""), std::string::npos);
    EXPECT_NE(r.output.find("\"direct_normal_illuminance_lux\""), std::string::npos);

    CommandResult text = RunNave(
        "sun --lat 39.742476 --lon -105.1786 --time 2003-10-17T12:30:30-07:00 "
        "--elevation 1830.14 --pressure 820 --temperature 11 --delta-t 67");
    ASSERT_EQ(text.exit_code, 0) << text.output;
    EXPECT_NE(text.output.find("azimuth                   194.34024°"), std::string::npos)
        << text.output;
    EXPECT_NE(text.output.find("zenith                    50.11162°"), std::string::npos)
        << text.output;

    CommandResult csv =
        RunNave("sun --lat 48.85 --lon 2.35 --time 2024-06-21T12:00+02:00 --spectrum");
    ASSERT_EQ(csv.exit_code, 0) << csv.output;
    EXPECT_EQ(csv.output.rfind("wavelength_nm,direct_normal_irradiance_w_m2_nm", 0), 0u);
    EXPECT_NE(csv.output.find("\n830,"), std::string::npos);
}

TEST(CliSunTest, BadInputExitsWithUsageError) {
    CommandResult no_zone = RunNave("sun --lat 45 --lon 0 --time 2003-10-17T12:30:30");
    EXPECT_EQ(no_zone.exit_code, 2);
    EXPECT_NE(no_zone.output.find("no time zone"), std::string::npos) << no_zone.output;
    CommandResult lat = RunNave("sun --lat 95 --lon 0 --time 2003-10-17T12:30:30Z");
    EXPECT_EQ(lat.exit_code, 2);
    EXPECT_NE(lat.output.find("--lat 95 out of range"), std::string::npos) << lat.output;
}

TEST(CliSpectrumTest, ColorCheckerPatchUnderD65AndErrors) {
    std::filesystem::path dir = std::filesystem::temp_directory_path() / "nave_cli_spectrum_test";
    std::filesystem::create_directories(dir);
    std::filesystem::path good = dir / "dark_skin.csv";
    {
        // BabelColor average dark skin, 380-730 nm (data/colorchecker_babelcolor_avg.csv).
        std::ofstream f(good);
        f << "# dark skin\nwavelength_nm,dark_skin\n";
        const double r[] = {0.05475, 0.05833, 0.06116, 0.06238, 0.06231, 0.06207, 0.06183, 0.06159,
                            0.06154, 0.06162, 0.06203, 0.06296, 0.06518, 0.07027, 0.07640, 0.07949,
                            0.08128, 0.08429, 0.09058, 0.10290, 0.11905, 0.13426, 0.14320, 0.14688,
                            0.15077, 0.15810, 0.16819, 0.17890, 0.18755, 0.18964, 0.18577, 0.18149,
                            0.18161, 0.18721, 0.19605, 0.20949};
        for (int i = 0; i < 36; ++i) f << 380 + 10 * i << "," << r[i] << "\n";
    }
    CommandResult r = RunNave("spectrum " + good.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // BabelColor/Wikipedia sRGB of dark skin: (115, 82, 68) = #735244.
    EXPECT_NE(r.output.find("#735244"), std::string::npos) << r.output;
    CommandResult json = RunNave("spectrum " + good.string() + " --illuminant A --json");
    ASSERT_EQ(json.exit_code, 0) << json.output;
    EXPECT_NE(json.output.find("\"name\": \"dark_skin\""), std::string::npos) << json.output;
    CommandResult sun = RunNave("spectrum " + good.string() +
                                " --illuminant sun:48.85,2.35,2024-06-21T12:00+02:00");
    EXPECT_EQ(sun.exit_code, 0) << sun.output;

    std::filesystem::path bad = dir / "bad.csv";
    {
        std::ofstream f(bad);
        f << "wavelength_nm,r\n400,0.5\n500,oops\n";
    }
    CommandResult malformed = RunNave("spectrum " + bad.string());
    EXPECT_EQ(malformed.exit_code, 1);
    EXPECT_NE(malformed.output.find("bad.csv:3: column 2: expected a number, found 'oops'"),
              std::string::npos)
        << malformed.output;
    CommandResult unknown = RunNave("spectrum " + good.string() + " --illuminant F11");
    EXPECT_EQ(unknown.exit_code, 2);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace nave
