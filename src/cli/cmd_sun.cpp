// `nave sun`: where the sun is and what light it sends to a place at a time (NREL SPA, clear-sky
// spectral transmittance), for checking a render's sun against the real one.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "src/cli/commands.h"
#include "src/core/color.h"
#include "src/render/scene/sun/sky.h"
#include "src/render/scene/sun/sun.h"

namespace nave::cli {

namespace {

struct SunOptions {
    double lat = 1000, lon = 1000;
    std::string time;
    double elevation_m = 0, pressure_hpa = -1, temperature_c = 15, turbidity = 3, delta_t_s = NAN;
    double ozone_atm_cm = 0.30, water_cm = 1.4;
    bool spectrum = false, json = false;
};

// Standard-atmosphere pressure at an altitude (ICAO 1993: p = 1013.25 (1 - 2.25577e-5 h)^5.25588).
double StandardPressureHpa(double elevation_m) {
    return 1013.25 * std::pow(1.0 - 2.25577e-5 * elevation_m, 5.25588);
}

std::string JsonNumber(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : "null"; }

Status RunSun(const SunOptions& o) {
    if (!(std::abs(o.lat) <= 90))
        return InvalidArgumentError("--lat {} out of range [-90, 90]", o.lat);
    if (!(std::abs(o.lon) <= 180))
        return InvalidArgumentError("--lon {} out of range [-180, 180]", o.lon);
    NAVE_ASSIGN_OR_RETURN(CivilTime t, ParseIso8601(o.time));
    SunInput in;
    in.time = t;
    in.latitude_deg = o.lat;
    in.longitude_deg = o.lon;
    in.elevation_m = o.elevation_m;
    // Without --delta-t, estimate ΔT for the date (matters for historical dates: ~11 min in 1236).
    double delta_t = std::isfinite(o.delta_t_s) ? o.delta_t_s : EstimateDeltaT(DecimalYear(t));
    in.delta_t_s = delta_t;
    in.atmosphere.pressure_hpa =
        o.pressure_hpa >= 0 ? o.pressure_hpa : StandardPressureHpa(o.elevation_m);
    in.atmosphere.temperature_c = o.temperature_c;
    in.atmosphere.turbidity = o.turbidity;
    in.atmosphere.ozone_atm_cm = o.ozone_atm_cm;
    in.atmosphere.water_vapour_cm = o.water_cm;
    NAVE_ASSIGN_OR_RETURN(Sun sun, ComputeSun(in));

    const SpaResult& p = sun.position;
    double lux = IlluminanceLux(sun.direct_normal_irradiance);
    double watts = 0;
    for (int i = 0; i < Spectrum::kNumSamples; ++i) watts += sun.direct_normal_irradiance.sample(i);
    bool lit = lux > 0;
    Chromaticity xy =
        lit ? XYZToChromaticity(SpectrumToXYZ(sun.direct_normal_irradiance)) : Chromaticity{};
    double cct = lit ? CctRobertson(xy) : NAN;
    double cct_mccamy = lit ? CctMcCamy(xy) : NAN;
    // Clear-sky zenith luminance of the Preetham et al. (1999) sky for the same sun and turbidity.
    double sky_zenith =
        lit ? PreethamSky(sun.direction, float(o.turbidity)).zenith_luminance() : NAN;

    if (o.spectrum && !o.json) {
        std::printf("wavelength_nm,direct_normal_irradiance_w_m2_nm,extraterrestrial_w_m2_nm\n");
        for (int i = 0; i < Spectrum::kNumSamples; ++i)
            std::printf("%d,%.6g,%.6g\n", int(kLambdaMinNm) + i,
                        sun.direct_normal_irradiance.sample(i),
                        sun.extraterrestrial_irradiance.sample(i));
        return Status::Ok();
    }
    if (o.json) {
        std::string out = "{\n";
        out += fmt::format("  \"time\": \"{}\",\n", FormatIso8601(t));
        out += fmt::format(
            "  \"latitude_deg\": {},\n  \"longitude_deg\": {},\n  \"elevation_m\": {},\n",
            JsonNumber(o.lat), JsonNumber(o.lon), JsonNumber(o.elevation_m));
        out +=
            fmt::format("  \"pressure_hpa\": {},\n  \"temperature_c\": {},\n  \"turbidity\": {},\n",
                        JsonNumber(in.atmosphere.pressure_hpa), JsonNumber(o.temperature_c),
                        JsonNumber(o.turbidity));
        out += fmt::format("  \"delta_t_s\": {},\n  \"julian_day\": {:.6f},\n", JsonNumber(delta_t),
                           p.jd);
        out += fmt::format(
            "  \"azimuth_deg\": {:.5f},\n  \"zenith_deg\": {:.5f},\n  \"elevation_deg\": {:.5f},\n",
            p.azimuth_deg, p.zenith_deg, p.elevation_deg);
        out += fmt::format("  \"refraction_deg\": {:.5f},\n  \"earth_sun_distance_au\": {:.8f},\n",
                           p.refraction_deg, sun.distance_au);
        out += fmt::format("  \"angular_radius_deg\": {:.5f},\n  \"air_mass\": {},\n",
                           sun.angular_radius_rad * 180 / M_PI,
                           lit ? JsonNumber(sun.air_mass) : "null");
        out += fmt::format("  \"direct_normal_illuminance_lux\": {},\n", JsonNumber(lux));
        out += fmt::format("  \"direct_normal_irradiance_360_830_w_m2\": {},\n", JsonNumber(watts));
        out += fmt::format("  \"cct_kelvin\": {},\n  \"cct_mccamy_kelvin\": {},\n", JsonNumber(cct),
                           JsonNumber(cct_mccamy));
        out += fmt::format("  \"sky_zenith_luminance_cd_m2\": {},\n", JsonNumber(sky_zenith));
        out += fmt::format("  \"chromaticity\": {{\"x\": {}, \"y\": {}}}",
                           lit ? JsonNumber(xy.x) : "null", lit ? JsonNumber(xy.y) : "null");
        if (o.spectrum) {
            out +=
                ",\n  \"spectrum\": {\"wavelength_nm_start\": 360, \"step_nm\": 1, "
                "\"direct_normal_irradiance_w_m2_nm\": [";
            for (int i = 0; i < Spectrum::kNumSamples; ++i)
                out +=
                    fmt::format("{}{:.6g}", i ? ", " : "", sun.direct_normal_irradiance.sample(i));
            out += "]}";
        }
        out += "\n}\n";
        std::fputs(out.c_str(), stdout);
        return Status::Ok();
    }
    std::printf("time                      %s (JD %.6f, delta T %.1f s%s)\n",
                FormatIso8601(t).c_str(), p.jd, delta_t,
                std::isfinite(o.delta_t_s) ? "" : ", estimated");
    std::printf("place                     %.6f° %s, %.6f° %s, %.1f m\n", std::abs(o.lat),
                o.lat >= 0 ? "N" : "S", std::abs(o.lon), o.lon >= 0 ? "E" : "W", o.elevation_m);
    std::printf("azimuth                   %.5f° (from north, clockwise)\n", p.azimuth_deg);
    std::printf("zenith                    %.5f° (refraction %.5f° at %.1f hPa, %.1f °C)\n",
                p.zenith_deg, p.refraction_deg, in.atmosphere.pressure_hpa, o.temperature_c);
    std::printf("elevation                 %.5f°\n", p.elevation_deg);
    std::printf("earth-sun distance        %.8f AU (disc radius %.4f°)\n", sun.distance_au,
                sun.angular_radius_rad * 180 / M_PI);
    if (!lit) {
        std::printf("the sun is below the horizon: no direct light\n");
        return Status::Ok();
    }
    std::printf("air mass                  %.4f (Kasten & Young 1989)\n", sun.air_mass);
    std::printf("direct normal illuminance %.0f lx\n", lux);
    std::printf(
        "direct normal irradiance  %.1f W/m² (360-830 nm; turbidity %.2g, ozone %.2f atm-cm)\n",
        watts, o.turbidity, o.ozone_atm_cm);
    std::printf("chromaticity              x %.4f, y %.4f\n", xy.x, xy.y);
    std::printf("correlated colour temp.   %.0f K (Robertson 1968; McCamy 1992: %.0f K)\n", cct,
                cct_mccamy);
    std::printf("sky zenith luminance      %.0f cd/m² (clear sky, Preetham et al. 1999)\n",
                sky_zenith);
    return Status::Ok();
}

}  // namespace

void RegisterSunCommand(CLI::App& app, CommandRun& run) {
    auto o = std::make_shared<SunOptions>();
    CLI::App* cmd = app.add_subcommand(
        "sun", "Sun position (NREL SPA) and clear-sky direct spectrum for a place and time");
    cmd->add_option("--lat", o->lat, "Latitude in degrees, north positive")->required();
    cmd->add_option("--lon", o->lon, "Longitude in degrees, east positive")->required();
    cmd->add_option("--time", o->time,
                    "ISO 8601 time with zone, e.g. 2003-10-17T12:30:30-07:00 or 2024-06-21T12:00Z")
        ->required();
    cmd->add_option("--elevation", o->elevation_m,
                    "Elevation above sea level in metres (default 0)");
    cmd->add_option("--pressure", o->pressure_hpa,
                    "Station pressure in hPa (default: standard atmosphere at the elevation)");
    cmd->add_option("--temperature", o->temperature_c,
                    "Air temperature in °C, for refraction (default 15)");
    cmd->add_option("--turbidity", o->turbidity,
                    "Preetham turbidity of the aerosols, 2 = very clear (default 3)");
    cmd->add_option("--delta-t", o->delta_t_s,
                    "ΔT = TT - UT1 in seconds (default: Espenak & Meeus estimate for the date)");
    cmd->add_option("--ozone", o->ozone_atm_cm, "Ozone column in atm-cm (default 0.30)");
    cmd->add_option("--water", o->water_cm, "Precipitable water in cm (default 1.4)");
    cmd->add_flag("--spectrum", o->spectrum,
                  "Print the direct normal spectral irradiance (CSV, 360-830 nm)");
    cmd->add_flag("--json", o->json, "Print JSON");
    cmd->callback([&run, o] { run = [o] { return RunSun(*o); }; });
}

}  // namespace nave::cli
