#include "src/render/scene/scene_config.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "src/core/file.h"
#include "src/core/memory.h"
#include "src/core/spectrum.h"
#include "src/render/scene/sun/spa.h"

namespace nave::render {

float SpectrumSpec::Evaluate(float lambda_nm) const {
    switch (kind) {
        case Kind::kConstant:
            return value * scale;
        case Kind::kTable: {
            if (wavelengths_nm.empty()) return 0.f;
            if (lambda_nm <= wavelengths_nm.front()) return values.front() * scale;
            if (lambda_nm >= wavelengths_nm.back()) return values.back() * scale;
            auto it = std::upper_bound(wavelengths_nm.begin(), wavelengths_nm.end(), lambda_nm);
            size_t i = size_t(it - wavelengths_nm.begin()) - 1;
            float f = (lambda_nm - wavelengths_nm[i]) / (wavelengths_nm[i + 1] - wavelengths_nm[i]);
            return ((1 - f) * values[i] + f * values[i + 1]) * scale;
        }
        case Kind::kBlackbody:
            return float(PlanckRelativeToPeak(lambda_nm, temperature_k)) * scale;
    }
    return 0.f;
}

namespace {

std::string Where(const std::string& file, const toml::source_region& r) {
    if (r.begin.line == 0) return file;
    return fmt::format("{}:{}:{}", file, r.begin.line, r.begin.column);
}

const char* TypeName(const toml::node& n) {
    switch (n.type()) {
        case toml::node_type::table:
            return "table";
        case toml::node_type::array:
            return "array";
        case toml::node_type::string:
            return "string";
        case toml::node_type::integer:
            return "integer";
        case toml::node_type::floating_point:
            return "float";
        case toml::node_type::boolean:
            return "boolean";
        case toml::node_type::date:
            return "date";
        case toml::node_type::time:
            return "time";
        case toml::node_type::date_time:
            return "date-time";
        default:
            return "nothing";
    }
}

/// Reads the keys of one table and remembers which were read, so that Finish() can reject the
/// others.
class TableReader {
  public:
    TableReader(const toml::table& table, std::string prefix, const std::string& file)
        : table_(table), prefix_(std::move(prefix)), file_(file) {}

    const std::string& file() const { return file_; }
    std::string Name(std::string_view key) const {
        return prefix_.empty() ? std::string(key) : prefix_ + "." + std::string(key);
    }
    std::string WhereIs(const toml::node& n) const { return Where(file_, n.source()); }
    std::string WhereTable() const { return Where(file_, table_.source()); }

    const toml::node* Take(std::string_view key) {
        const toml::node* n = table_.get(key);
        if (n != nullptr) used_.insert(std::string(key));
        return n;
    }
    bool Has(std::string_view key) const { return table_.get(key) != nullptr; }

    Status TypeError(std::string_view key, const toml::node& n, const char* expected) const {
        return InvalidArgumentError("{}: {}: expected {}, found {}", WhereIs(n), Name(key),
                                    expected, TypeName(n));
    }
    Status RangeError(std::string_view key, const toml::node& n, const std::string& what) const {
        return InvalidArgumentError("{}: {}: {}", WhereIs(n), Name(key), what);
    }

    Status Double(std::string_view key, double* out, double lo = -INFINITY, double hi = INFINITY) {
        const toml::node* n = Take(key);
        if (n == nullptr) return Status::Ok();
        std::optional<double> v = n->is_number() ? n->value<double>() : std::nullopt;
        if (!v) return TypeError(key, *n, "a number");
        if (!(*v >= lo && *v <= hi)) {
            return RangeError(key, *n, fmt::format("{} is out of range [{}, {}]", *v, lo, hi));
        }
        *out = *v;
        return Status::Ok();
    }
    Status Float(std::string_view key, float* out, double lo = -INFINITY, double hi = INFINITY) {
        double v = *out;
        NAVE_RETURN_IF_ERROR(Double(key, &v, lo, hi));
        *out = float(v);
        return Status::Ok();
    }
    template <typename I>
    Status Int(std::string_view key, I* out, int64_t lo, int64_t hi) {
        const toml::node* n = Take(key);
        if (n == nullptr) return Status::Ok();
        if (!n->is_integer()) return TypeError(key, *n, "an integer");
        int64_t v = *n->value<int64_t>();
        if (v < lo || v > hi)
            return RangeError(key, *n, fmt::format("{} is out of range [{}, {}]", v, lo, hi));
        *out = I(v);
        return Status::Ok();
    }
    Status Bool(std::string_view key, bool* out) {
        const toml::node* n = Take(key);
        if (n == nullptr) return Status::Ok();
        if (!n->is_boolean()) return TypeError(key, *n, "true or false");
        *out = *n->value<bool>();
        return Status::Ok();
    }
    Status String(std::string_view key, std::string* out) {
        const toml::node* n = Take(key);
        if (n == nullptr) return Status::Ok();
        if (!n->is_string()) return TypeError(key, *n, "a string");
        *out = *n->value<std::string>();
        return Status::Ok();
    }
    /// A string naming one of `choices`; anything else is an error listing them.
    template <typename E>
    Status Choice(std::string_view key, std::initializer_list<std::pair<const char*, E>> choices,
                  E* out) {
        const toml::node* n = Take(key);
        if (n == nullptr) return Status::Ok();
        if (!n->is_string()) return TypeError(key, *n, "a string");
        const std::string value = *n->value<std::string>();
        std::vector<std::string> names;
        for (const auto& [name, e] : choices) {
            if (value == name) {
                *out = e;
                return Status::Ok();
            }
            names.push_back(fmt::format("\"{}\"", name));
        }
        return RangeError(key, *n,
                          fmt::format("'{}' (expected {})", value, fmt::join(names, " or ")));
    }
    Status Vec3(std::string_view key, Vec3f* out) {
        const toml::node* n = Take(key);
        if (n == nullptr) return Status::Ok();
        const toml::array* a = n->as_array();
        if (a == nullptr || a->size() != 3) return TypeError(key, *n, "an array of 3 numbers");
        for (int i = 0; i < 3; ++i) {
            if (!(*a)[size_t(i)].is_number()) return TypeError(key, *n, "an array of 3 numbers");
            (*out)[i] = float(*(*a)[size_t(i)].value<double>());
        }
        return Status::Ok();
    }
    Status Spectrum(std::string_view key, SpectrumSpec* out);
    StatusOr<std::optional<SpectrumSpec>> OptionalSpectrum(std::string_view key) {
        if (!Has(key)) return std::optional<SpectrumSpec>();
        SpectrumSpec s;
        NAVE_RETURN_IF_ERROR(Spectrum(key, &s));
        return std::optional<SpectrumSpec>(s);
    }

    /// A sub-table, or nullptr if absent; an error if the key holds something else.
    StatusOr<const toml::table*> Table(std::string_view key) {
        const toml::node* n = Take(key);
        if (n == nullptr) return static_cast<const toml::table*>(nullptr);
        if (!n->is_table()) return TypeError(key, *n, "a table");
        return n->as_table();
    }

    /// Every key of the table that nothing read is an error naming it and its place.
    Status Finish() const {
        for (auto&& [k, v] : table_) {
            if (used_.count(std::string(k.str())) == 0) {
                std::vector<std::string> known(used_.begin(), used_.end());
                return InvalidArgumentError(
                    "{}: unknown key '{}'{}", Where(file_, k.source()), Name(k.str()),
                    used_.empty() ? std::string()
                                  : fmt::format(" (keys read here: {})", fmt::join(known, ", ")));
            }
        }
        return Status::Ok();
    }

  private:
    const toml::table& table_;
    std::string prefix_;
    const std::string& file_;
    std::set<std::string> used_;
};

Status TableReader::Spectrum(std::string_view key, SpectrumSpec* out) {
    const toml::node* n = Take(key);
    if (n == nullptr) return Status::Ok();
    if (n->is_number()) {
        *out = SpectrumSpec::Constant(float(*n->value<double>()));
        return Status::Ok();
    }
    if (!n->is_table())
        return TypeError(key, *n, "a number or a table {wavelengths_nm, values} / {blackbody_k}");
    TableReader t(*n->as_table(), Name(key), file_);
    SpectrumSpec s;
    NAVE_RETURN_IF_ERROR(t.Float("scale", &s.scale));
    if (t.Has("blackbody_k")) {
        s.kind = SpectrumSpec::Kind::kBlackbody;
        NAVE_RETURN_IF_ERROR(t.Float("blackbody_k", &s.temperature_k, 100, 1e6));
    } else if (t.Has("wavelengths_nm") || t.Has("values")) {
        s.kind = SpectrumSpec::Kind::kTable;
        for (auto [name, vec] :
             {std::pair<const char*, std::vector<float>*>{"wavelengths_nm", &s.wavelengths_nm},
              {"values", &s.values}}) {
            const toml::node* a = t.Take(name);
            if (a == nullptr) {
                return InvalidArgumentError(
                    "{}: {}: a spectrum table needs both wavelengths_nm and values", WhereIs(*n),
                    Name(key));
            }
            if (!a->is_array()) return t.TypeError(name, *a, "an array of numbers");
            for (const toml::node& e : *a->as_array()) {
                if (!e.is_number()) return t.TypeError(name, *a, "an array of numbers");
                vec->push_back(float(*e.value<double>()));
            }
        }
        if (s.wavelengths_nm.size() != s.values.size() || s.values.empty()) {
            return InvalidArgumentError(
                "{}: {}: wavelengths_nm has {} entries and values {} (expected equal, > 0)",
                WhereIs(*n), Name(key), s.wavelengths_nm.size(), s.values.size());
        }
        for (size_t i = 1; i < s.wavelengths_nm.size(); ++i) {
            if (!(s.wavelengths_nm[i] > s.wavelengths_nm[i - 1])) {
                return InvalidArgumentError(
                    "{}: {}.wavelengths_nm must increase (entry {}: {} after {})", WhereIs(*n),
                    Name(key), i, s.wavelengths_nm[i], s.wavelengths_nm[i - 1]);
            }
        }
    } else if (t.Has("csv")) {
        // A column of a CSV spectra file, looked up beside the config, then in nave's data
        // directory.
        s.kind = SpectrumSpec::Kind::kTable;
        std::string csv, column;
        NAVE_RETURN_IF_ERROR(t.String("csv", &csv));
        NAVE_RETURN_IF_ERROR(t.String("column", &column));
        std::filesystem::path path = std::filesystem::path(file_).parent_path() / csv;
        if (!std::filesystem::exists(path)) path = std::filesystem::path(NAVE_DATA_DIR) / csv;
        StatusOr<SpectraTable> table = LoadSpectraCsv(path);
        if (!table.ok()) {
            return InvalidArgumentError("{}: {}.csv: {}", WhereIs(*n), Name(key),
                                        table.status().message());
        }
        auto it = std::find(table->names.begin(), table->names.end(), column);
        if (it == table->names.end()) {
            return InvalidArgumentError("{}: {}.column: '{}' is not a column of {} (columns: {})",
                                        WhereIs(*n), Name(key), column, path.string(),
                                        fmt::join(table->names, ", "));
        }
        const auto& values = table->columns[size_t(it - table->names.begin())];
        for (size_t i = 0; i < values.size(); ++i) {
            s.wavelengths_nm.push_back(float(table->lambda_nm[i]));
            s.values.push_back(float(values[i]));
        }
    } else if (t.Has("value")) {
        NAVE_RETURN_IF_ERROR(t.Float("value", &s.value));
    } else {
        return InvalidArgumentError(
            "{}: {}: a spectrum table needs value, wavelengths_nm + values, csv + column, or "
            "blackbody_k",
            WhereIs(*n), Name(key));
    }
    NAVE_RETURN_IF_ERROR(t.Finish());
    *out = std::move(s);
    return Status::Ok();
}

int DaysInMonth(int year, int month) {
    static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    return month == 2 && leap ? 29 : kDays[month - 1];
}

Status ParseCamera(TableReader& r, CameraConfig* c) {
    NAVE_RETURN_IF_ERROR(r.Vec3("position", &c->position));
    NAVE_RETURN_IF_ERROR(r.Vec3("look_at", &c->look_at));
    NAVE_RETURN_IF_ERROR(r.Vec3("up", &c->up));
    NAVE_RETURN_IF_ERROR(r.Float("fov_deg", &c->fov_deg, 0.01, 179.9));
    if (const toml::node* n = r.Take("resolution")) {
        const toml::array* a = n->as_array();
        if (a == nullptr || a->size() != 2 || !(*a)[0].is_integer() || !(*a)[1].is_integer()) {
            return r.TypeError("resolution", *n, "[width, height] integers");
        }
        c->width = int(*(*a)[0].value<int64_t>());
        c->height = int(*(*a)[1].value<int64_t>());
        if (c->width < 1 || c->height < 1 || c->width > 65536 || c->height > 65536) {
            return r.RangeError(
                "resolution", *n,
                fmt::format("{}x{} is out of range [1, 65536]", c->width, c->height));
        }
    }
    NAVE_RETURN_IF_ERROR(r.Float("lens_radius_m", &c->lens_radius_m, 0, 1e3));
    NAVE_RETURN_IF_ERROR(r.Float("focus_distance_m", &c->focus_distance_m, 0, 1e9));
    if (Length(c->look_at - c->position) == 0) {
        return InvalidArgumentError("{}: camera.look_at equals camera.position", r.WhereTable());
    }
    if (Length(Cross(c->look_at - c->position, c->up)) == 0) {
        return InvalidArgumentError("{}: camera.up is parallel to the view direction",
                                    r.WhereTable());
    }
    return r.Finish();
}

Status ParseSun(TableReader& r, SunConfig* s) {
    s->enabled = true;
    NAVE_RETURN_IF_ERROR(r.Bool("enabled", &s->enabled));
    if (const toml::node* n = r.Take("datetime")) {
        if (n->is_string()) {
            StatusOr<DateTime> dt = ParseDateTime(*n->value<std::string>());
            if (!dt.ok())
                return InvalidArgumentError("{}: sun.datetime: {}", r.WhereIs(*n),
                                            dt.status().message());
            s->when = *dt;
        } else if (const auto* v = n->as_date_time()) {
            const toml::date_time& d = v->get();
            if (!d.offset)
                return r.RangeError("datetime", *n, "needs a UTC offset (e.g. +02:00 or Z)");
            s->when =
                DateTime{d.date.year,      d.date.month,  d.date.day,
                         d.time.hour,      d.time.minute, d.time.second + d.time.nanosecond * 1e-9,
                         d.offset->minutes};
        } else {
            return r.TypeError("datetime", *n,
                               "a date-time with offset (2025-06-21T08:00:00+02:00)");
        }
    } else if (s->enabled && !r.Has("direction")) {
        return InvalidArgumentError(
            "{}: sun: needs datetime (and latitude_deg, longitude_deg) or direction",
            r.WhereTable());
    }
    NAVE_RETURN_IF_ERROR(r.Double("latitude_deg", &s->latitude_deg, -90, 90));
    NAVE_RETURN_IF_ERROR(r.Double("longitude_deg", &s->longitude_deg, -180, 180));
    NAVE_RETURN_IF_ERROR(r.Double("elevation_m", &s->elevation_m, -500, 9000));
    NAVE_RETURN_IF_ERROR(r.Double("pressure_mbar", &s->pressure_mbar, 300, 1200));
    NAVE_RETURN_IF_ERROR(r.Double("temperature_c", &s->temperature_c, -90, 60));
    NAVE_RETURN_IF_ERROR(r.Double("turbidity", &s->turbidity, 1, 20));
    NAVE_RETURN_IF_ERROR(r.Float("scale", &s->scale, 0, 1e9));
    NAVE_RETURN_IF_ERROR(r.Float("angular_radius_deg", &s->angular_radius_deg, 1e-4, 10));
    if (r.Has("direction")) {
        Vec3f d;
        NAVE_RETURN_IF_ERROR(r.Vec3("direction", &d));
        if (Length(d) == 0)
            return InvalidArgumentError("{}: sun.direction must not be zero", r.WhereTable());
        s->direction = Normalize(d);
    }
    NAVE_ASSIGN_OR_RETURN(s->radiance, r.OptionalSpectrum("radiance"));
    return r.Finish();
}

Status ParseSky(TableReader& r, SkyConfig* s) {
    std::string type = "uniform";
    const toml::node* tn = r.Has("type") ? r.Take("type") : nullptr;
    if (tn != nullptr) {
        if (!tn->is_string()) return r.TypeError("type", *tn, "a string");
        type = *tn->value<std::string>();
    }
    if (type == "uniform") {
        s->kind = SkyConfig::Kind::kUniform;
        s->radiance = SpectrumSpec::Constant(1.f);
        NAVE_RETURN_IF_ERROR(r.Spectrum("radiance", &s->radiance));
    } else if (type == "preetham") {
        s->kind = SkyConfig::Kind::kPreetham;
        double t = 0;
        if (r.Has("turbidity")) {
            NAVE_RETURN_IF_ERROR(r.Double("turbidity", &t, 1.7, 10));
            s->turbidity = t;
        }
        NAVE_RETURN_IF_ERROR(r.Float("scale", &s->scale, 0, 1e9));
        NAVE_ASSIGN_OR_RETURN(s->ground_albedo, r.OptionalSpectrum("ground_albedo"));
        if (s->ground_albedo) {
            for (float l = kLambdaMinNm; l <= kLambdaMaxNm; l += 1) {
                const float a = s->ground_albedo->Evaluate(l);
                if (!(a >= 0 && a <= 1)) {
                    return InvalidArgumentError(
                        "{}: {}: {} at {} nm, expected an albedo within [0, 1]", r.WhereTable(),
                        r.Name("ground_albedo"), a, l);
                }
            }
        }
    } else if (type == "none") {
        s->kind = SkyConfig::Kind::kNone;
    } else {
        return r.RangeError(
            "type", *tn,
            fmt::format("'{}' is not a sky type (expected uniform, preetham or none)", type));
    }
    return r.Finish();
}

Status ParseLight(TableReader& r, LightConfig* l) {
    l->where = r.WhereTable();
    std::string type;
    const toml::node* tn = r.Take("type");
    if (tn == nullptr)
        return InvalidArgumentError("{}: {}: missing 'type' (directional, point or spot)", l->where,
                                    r.Name(""));
    if (!tn->is_string()) return r.TypeError("type", *tn, "a string");
    type = *tn->value<std::string>();
    if (type == "directional") {
        l->kind = LightConfig::Kind::kDirectional;
    } else if (type == "point") {
        l->kind = LightConfig::Kind::kPoint;
    } else if (type == "spot") {
        l->kind = LightConfig::Kind::kSpot;
    } else {
        return r.RangeError(
            "type", *tn, fmt::format("'{}' is not a light type (directional, point, spot)", type));
    }
    if (l->kind != LightConfig::Kind::kPoint) {
        NAVE_RETURN_IF_ERROR(r.Vec3("direction", &l->direction));
        if (Length(l->direction) == 0)
            return InvalidArgumentError("{}: {}.direction must not be zero", l->where, r.Name(""));
        l->direction = Normalize(l->direction);
    }
    if (l->kind != LightConfig::Kind::kDirectional)
        NAVE_RETURN_IF_ERROR(r.Vec3("position", &l->position));
    if (l->kind == LightConfig::Kind::kSpot) {
        NAVE_RETURN_IF_ERROR(r.Float("cone_deg", &l->cone_deg, 0.01, 90));
        l->falloff_start_deg = l->cone_deg;
        NAVE_RETURN_IF_ERROR(r.Float("falloff_start_deg", &l->falloff_start_deg, 0, l->cone_deg));
    }
    const char* key = l->kind == LightConfig::Kind::kDirectional ? "irradiance" : "intensity";
    if (!r.Has(key)) return InvalidArgumentError("{}: {}: missing '{}'", l->where, r.Name(""), key);
    NAVE_RETURN_IF_ERROR(r.Spectrum(key, &l->spectrum));
    return r.Finish();
}

/// The emission keys of a medium table (MediumConfig::emission).
Status ParseMediumEmission(TableReader& r, MediumConfig* m) {
    if (r.Has("emission")) {
        SpectrumSpec emission;
        NAVE_RETURN_IF_ERROR(r.Spectrum("emission", &emission));
        m->emission = emission;
    }
    const bool file_grid = !m->grid.empty();
    for (const auto& [key, out] : {std::pair{"emission_grid", &m->emission_grid},
                                   {"temperature_grid", &m->temperature_grid}}) {
        if (!r.Has(key)) continue;
        if (!file_grid)
            return InvalidArgumentError(
                "{}: {}.{} names a grid of the medium's .vdb file: give that file as 'grid'{}",
                m->where, m->name, key,
                m->stored_grid ? " (a store holds the density grid only)" : "");
        NAVE_RETURN_IF_ERROR(r.String(key, out));
    }
    if (!m->temperature_grid.empty() && m->emission)
        return InvalidArgumentError(
            "{}: {}: give emission (a radiance) or temperature_grid (a black body's), not both",
            m->where, m->name);
    if (!m->emission_grid.empty() && !m->emission)
        return InvalidArgumentError(
            "{}: {}.emission_grid scales a radiance: give it as 'emission' (W m^-2 sr^-1 nm^-1)",
            m->where, m->name);
    if (r.Has("temperature_scale") && m->temperature_grid.empty())
        return InvalidArgumentError("{}: {}.temperature_scale needs a temperature_grid", m->where,
                                    m->name);
    if (r.Has("emission_scale") && !m->emits())
        return InvalidArgumentError("{}: {}.emission_scale needs an emission or a temperature_grid",
                                    m->where, m->name);
    NAVE_RETURN_IF_ERROR(r.Float("temperature_scale", &m->temperature_scale, 0, 1e9));
    return r.Float("emission_scale", &m->emission_scale, 0, 1e9);
}

/// [medium], or with `inside_solid` a material's medium table (named `name`), which fills the
/// solid's inside and takes no box or grid.
Status ParseMedium(TableReader& r, MediumConfig* m, const std::string& name = "medium",
                   bool inside_solid = false) {
    m->where = r.WhereTable();
    m->name = name;
    if (inside_solid) {
        for (const char* key : {"box_min", "box_max", "grid", "grid_name", "density_scale",
                                "emission_grid", "temperature_grid", "temperature_scale"})
            if (r.Has(key))
                return InvalidArgumentError(
                    "{}: {}.{}: a solid's medium fills its inside, the whole of it: it takes "
                    "sigma_a and sigma_s (or extinction and albedo), g, emission and "
                    "emission_scale only",
                    m->where, name, key);
    }
    if (r.Has("box_min") != r.Has("box_max"))
        return InvalidArgumentError(
            "{}: {}: give both box_min and box_max, or neither (the "
            "model's bounds)",
            m->where, r.Name(""));
    if (r.Has("box_min")) {
        Bounds3f box;
        NAVE_RETURN_IF_ERROR(r.Vec3("box_min", &box.min));
        NAVE_RETURN_IF_ERROR(r.Vec3("box_max", &box.max));
        if (!(box.min.x < box.max.x && box.min.y < box.max.y && box.min.z < box.max.z))
            return InvalidArgumentError("{}: {}: box_min must be below box_max on every axis",
                                        m->where, r.Name(""));
        m->box = box;
    }
    if (r.Has("grid")) {
        if (r.Has("box_min"))
            return InvalidArgumentError(
                "{}: {}: give a grid or a box (box_min, box_max), not both: a grid's medium fills "
                "its voxels",
                m->where, r.Name(""));
        std::string grid;
        NAVE_RETURN_IF_ERROR(r.String("grid", &grid));
        if (grid == kStoredGrid) {
            m->stored_grid = true;
            if (r.Has("grid_name"))
                return InvalidArgumentError(
                    "{}: {}: grid_name names a grid of a .vdb file; grid = \"{}\" is the one "
                    "grid the store holds",
                    m->where, r.Name(""), kStoredGrid);
        } else {
            m->grid = std::filesystem::path(r.file()).parent_path() / grid;
            NAVE_RETURN_IF_ERROR(r.String("grid_name", &m->grid_name));
        }
        NAVE_RETURN_IF_ERROR(r.Float("density_scale", &m->density_scale, 0, 1e9));
    } else if (r.Has("grid_name") || r.Has("density_scale")) {
        return InvalidArgumentError("{}: {}: grid_name and density_scale need a grid", m->where,
                                    r.Name(""));
    }
    const bool coefficients = r.Has("sigma_a") || r.Has("sigma_s");
    const bool extinction = r.Has("extinction") || r.Has("albedo");
    if (coefficients && extinction)
        return InvalidArgumentError(
            "{}: {}: give sigma_s and sigma_a, or extinction and albedo, not both", m->where,
            r.Name(""));
    if (!coefficients && !extinction)
        return InvalidArgumentError(
            "{}: {}: missing 'sigma_s' and 'sigma_a' (the scattering and absorption coefficients, "
            "m^-1), or 'extinction' and 'albedo'",
            m->where, r.Name(""));
    if (extinction) {
        if (!r.Has("extinction") || !r.Has("albedo"))
            return InvalidArgumentError("{}: {}: 'extinction' and 'albedo' go together", m->where,
                                        r.Name(""));
        SpectrumSpec sigma_t, albedo;
        NAVE_RETURN_IF_ERROR(r.Spectrum("extinction", &sigma_t));
        NAVE_RETURN_IF_ERROR(r.Spectrum("albedo", &albedo));
        m->extinction_albedo = std::pair{sigma_t, albedo};
    }
    if (r.Has("sigma_a")) NAVE_RETURN_IF_ERROR(r.Spectrum("sigma_a", &m->sigma_a));
    if (r.Has("sigma_s")) NAVE_RETURN_IF_ERROR(r.Spectrum("sigma_s", &m->sigma_s));
    NAVE_RETURN_IF_ERROR(r.Float("g", &m->g, -0.99, 0.99));
    NAVE_RETURN_IF_ERROR(ParseMediumEmission(r, m));
    return r.Finish();
}

/// The texture keys every material type takes.
Status ParseMaterialTextures(TableReader& r, MaterialConfig* m) {
    NAVE_RETURN_IF_ERROR(r.Bool("textures", &m->textures));
    return r.Float("emission_scale", &m->emission_scale, 0, 1e9);
}

/// The material's `medium` table, if any: what fills a solid dielectric's inside.
Status ParseMaterialMedium(TableReader& r, MaterialConfig* m) {
    NAVE_ASSIGN_OR_RETURN(const toml::table* medium, r.Table("medium"));
    if (medium == nullptr) return Status::Ok();
    const std::string name = r.Name("medium");
    TableReader t(*medium, name, r.file());
    MediumConfig config;
    NAVE_RETURN_IF_ERROR(ParseMedium(t, &config, name, /*inside_solid=*/true));
    m->medium = std::move(config);
    return Status::Ok();
}

Status ParseMaterial(TableReader& r, MaterialConfig* m) {
    m->where = r.WhereTable();
    NAVE_RETURN_IF_ERROR(ParseMaterialMedium(r, m));
    if (r.Has("builtin")) {
        // A named material of nave's physics library (limestone, glass_blue, gold, bk7...).
        if (r.Has("type")) {
            return InvalidArgumentError("{}: {}: give either 'builtin' or 'type', not both",
                                        m->where, r.Name(""));
        }
        NAVE_RETURN_IF_ERROR(r.String("builtin", &m->builtin));
        NAVE_ASSIGN_OR_RETURN(m->emission, r.OptionalSpectrum("emission"));
        NAVE_RETURN_IF_ERROR(r.Bool("portal", &m->portal));
        NAVE_RETURN_IF_ERROR(ParseMaterialTextures(r, m));
        return r.Finish();
    }
    std::string type = "diffuse";
    const toml::node* tn = r.Take("type");
    if (tn != nullptr) {
        if (!tn->is_string()) return r.TypeError("type", *tn, "a string");
        type = *tn->value<std::string>();
    }
    if (type == "diffuse") {
        m->kind = MaterialConfig::Kind::kDiffuse;
        const toml::node* reflectance = r.Has("reflectance") ? r.Take("reflectance") : nullptr;
        if (reflectance != nullptr && reflectance->is_string()) {
            if (*reflectance->value<std::string>() != "model") {
                return r.TypeError("reflectance", *reflectance,
                                   "a number, a table, or the string \"model\"");
            }
            m->reflectance_from_model = true;
        } else {
            NAVE_RETURN_IF_ERROR(r.Spectrum("reflectance", &m->reflectance));
        }
    } else if (type == "conductor") {
        m->kind = MaterialConfig::Kind::kConductor;
        m->eta = SpectrumSpec::Constant(0.2f);
        m->k = SpectrumSpec::Constant(3.0f);
        NAVE_RETURN_IF_ERROR(r.Spectrum("eta", &m->eta));
        NAVE_RETURN_IF_ERROR(r.Spectrum("k", &m->k));
        NAVE_RETURN_IF_ERROR(r.Float("roughness", &m->roughness, 0, 1));
    } else if (type == "dielectric" || type == "thin_dielectric") {
        m->kind = type == "dielectric" ? MaterialConfig::Kind::kDielectric
                                       : MaterialConfig::Kind::kThinDielectric;
        NAVE_RETURN_IF_ERROR(r.Spectrum("eta", &m->eta));
        NAVE_RETURN_IF_ERROR(r.Float("roughness", &m->roughness, 0, 1));
        // The absorbing part of the index: k, or the paper's κ (ñ = n(1 + iκ)), not both.
        if (r.Has("k") && r.Has("kappa")) {
            return InvalidArgumentError(
                "{}: {}: give either k (ñ = n + ik) or kappa (ñ = n(1 + iκ)), not both", m->where,
                r.Name(""));
        }
        m->glass_k_is_kappa = r.Has("kappa");
        NAVE_ASSIGN_OR_RETURN(m->glass_k, r.OptionalSpectrum(m->glass_k_is_kappa ? "kappa" : "k"));
        if (m->kind == MaterialConfig::Kind::kThinDielectric && m->glass_k) {
            if (!r.Has("thickness_mm")) {
                return InvalidArgumentError("{}: {}: k or kappa needs the pane's thickness_mm",
                                            m->where, r.Name(""));
            }
            if (r.Has("transmittance") || r.Has("total_transmittance")) {
                return InvalidArgumentError(
                    "{}: {}: give the pane's absorption once: k or kappa with thickness_mm, "
                    "transmittance "
                    "(internal) or total_transmittance",
                    m->where, r.Name(""));
            }
            NAVE_RETURN_IF_ERROR(r.Float("thickness_mm", &m->thickness_mm, 1e-3f, 1e3f));
        }
        if (m->kind == MaterialConfig::Kind::kThinDielectric) {
            if (r.Has("transmittance") && r.Has("total_transmittance")) {
                return InvalidArgumentError(
                    "{}: {}: give either transmittance (internal) or total_transmittance", m->where,
                    r.Name(""));
            }
            NAVE_RETURN_IF_ERROR(r.Spectrum("transmittance", &m->transmittance));
            NAVE_ASSIGN_OR_RETURN(m->total_transmittance,
                                  r.OptionalSpectrum("total_transmittance"));
        }
    } else if (type == "black") {
        m->kind = MaterialConfig::Kind::kBlack;
    } else {
        return r.RangeError(
            "type", *tn,
            fmt::format("'{}' is not a material type (diffuse, conductor, dielectric, "
                        "thin_dielectric, black)",
                        type));
    }
    if (m->medium && m->kind != MaterialConfig::Kind::kDielectric)
        return InvalidArgumentError(
            "{}: {}: only a solid dielectric (type = \"dielectric\") has an inside to fill; a "
            "{} material has none",
            m->medium->where, m->medium->name, type);
    NAVE_ASSIGN_OR_RETURN(m->emission, r.OptionalSpectrum("emission"));
    NAVE_RETURN_IF_ERROR(r.Bool("portal", &m->portal));
    NAVE_RETURN_IF_ERROR(ParseMaterialTextures(r, m));
    return r.Finish();
}

Status ParseTextures(TableReader& r, TextureConfig* t) {
    NAVE_RETURN_IF_ERROR(r.Bool("enabled", &t->enabled));
    if (const toml::node* n = r.Take("cache")) {
        if (!n->is_string()) return r.TypeError("cache", *n, "a size such as \"256M\"");
        StatusOr<uint64_t> bytes = ParseByteSize(*n->value<std::string>());
        if (!bytes.ok()) return r.RangeError("cache", *n, bytes.status().message());
        t->cache_bytes = *bytes;
    }
    NAVE_RETURN_IF_ERROR(r.Double("memory_share", &t->memory_share, 0.0, 0.9));
    return r.Finish();
}

Status ParseRender(TableReader& r, RenderSettings* s) {
    std::string mode = "path";
    NAVE_RETURN_IF_ERROR(r.String("mode", &mode));
    if (mode == "path") {
        s->mode = RenderSettings::Mode::kPath;
    } else if (mode == "photon") {
        s->mode = RenderSettings::Mode::kPhoton;
    } else {
        return InvalidArgumentError("{}: render.mode: '{}' (expected \"path\" or \"photon\")",
                                    r.WhereTable(), mode);
    }
    NAVE_RETURN_IF_ERROR(r.Int("spp", &s->spp, 1, 1 << 20));
    NAVE_RETURN_IF_ERROR(r.Double("time_limit_s", &s->time_limit_s, 0, 1e7));
    NAVE_RETURN_IF_ERROR(r.Double("noise_target", &s->noise_target, 0, 100));
    NAVE_RETURN_IF_ERROR(r.Int("iterations", &s->iterations, 1, 1 << 20));
    // A photon's index within its iteration keys its random numbers in 32 bits (RayRecord::pixel):
    // beyond that, photons would repeat each other's.
    NAVE_RETURN_IF_ERROR(
        r.Int("photons_per_iteration", &s->photons_per_iteration, 1, int64_t(UINT32_MAX)));
    NAVE_RETURN_IF_ERROR(r.Float("initial_radius_m", &s->initial_radius_m, 0, 1e6));
    NAVE_RETURN_IF_ERROR(r.Float("alpha", &s->alpha, 0.01, 1));
    // A ray counts its scatterings in a byte (RayRecord::depth).
    NAVE_RETURN_IF_ERROR(r.Int("max_depth", &s->max_depth, 1, 255));
    NAVE_RETURN_IF_ERROR(r.Int("seed", &s->seed, 0, INT64_MAX));
    NAVE_RETURN_IF_ERROR(r.Int("threads", &s->threads, 0, 4096));
    s->wave_paths_chosen = r.Has("wave_paths");
    NAVE_RETURN_IF_ERROR(r.Int("wave_paths", &s->wave_paths, 1024, int64_t(1) << 30));
    NAVE_RETURN_IF_ERROR(r.Choice("photon_target",
                                  {{"bounds", RenderSettings::PhotonTarget::kBounds},
                                   {"portals", RenderSettings::PhotonTarget::kPortals}},
                                  &s->photon_target));
    NAVE_RETURN_IF_ERROR(r.Choice("sky_sampling",
                                  {{"uniform", RenderSettings::SkySampling::kUniform},
                                   {"portals", RenderSettings::SkySampling::kPortals}},
                                  &s->sky_sampling));
    NAVE_RETURN_IF_ERROR(r.Choice("sky_direct",
                                  {{"sampled", RenderSettings::SkyDirect::kSampled},
                                   {"photons", RenderSettings::SkyDirect::kPhotons}},
                                  &s->sky_direct));
    NAVE_RETURN_IF_ERROR(r.Bool("final_gather", &s->final_gather));
    if (s->final_gather && s->sky_direct == RenderSettings::SkyDirect::kPhotons) {
        return InvalidArgumentError(
            "{}: render.final_gather = true and render.sky_direct = \"photons\" exclude each "
            "other: with final gathering the sky's direct light is next-event estimated "
            "(sky_direct = \"sampled\") and its photons are read one bounce away",
            r.WhereTable());
    }
    NAVE_RETURN_IF_ERROR(r.Bool("path_guiding", &s->path_guiding));
    NAVE_RETURN_IF_ERROR(r.Choice(
        "lod", {{"auto", RenderSettings::Lod::kAuto}, {"full", RenderSettings::Lod::kFull}},
        &s->lod));
    return r.Finish();
}

Status ParseOutput(TableReader& r, OutputConfig* o) {
    if (const toml::node* n = r.Has("white_balance") ? r.Take("white_balance") : nullptr) {
        if (!n->is_string()) return r.TypeError("white_balance", *n, "a string");
        o->white_balance = *n->value<std::string>();
        const std::string& w = o->white_balance;
        bool kelvin =
            w.size() > 1 && w.back() == 'K' &&
            std::all_of(w.begin(), w.end() - 1, [](char c) { return c >= '0' && c <= '9'; });
        if (w != "none" && w != "D65" && w != "D50" && w != "scene" && !kelvin) {
            return r.RangeError(
                "white_balance", *n,
                fmt::format("'{}' (expected none, D65, D50, scene or a temperature like \"5000K\")",
                            w));
        }
    }
    if (const toml::node* n = r.Has("adaptation") ? r.Take("adaptation") : nullptr) {
        if (!n->is_string()) return r.TypeError("adaptation", *n, "a string");
        std::optional<AdaptationMethod> m = ParseAdaptationMethod(*n->value<std::string>());
        if (!m) {
            return r.RangeError(
                "adaptation", *n,
                fmt::format("'{}' (expected bradford, von_kries, xyz_scaling, cat02 or cat16)",
                            *n->value<std::string>()));
        }
        o->adaptation = *m;
    }
    NAVE_RETURN_IF_ERROR(r.Float("exposure_ev", &o->exposure_ev, -30, 30));
    NAVE_RETURN_IF_ERROR(r.Choice(
        "exposure",
        {{"auto", OutputConfig::Exposure::kAuto}, {"physical", OutputConfig::Exposure::kPhysical}},
        &o->exposure));
    if (r.Has("ev100")) {
        double ev = 0;
        NAVE_RETURN_IF_ERROR(r.Double("ev100", &ev, -10, 30));
        o->ev100 = ev;
    }
    NAVE_RETURN_IF_ERROR(r.Choice("tone",
                                  {{"clip", OutputConfig::Tone::kClip},
                                   {"hue_preserving", OutputConfig::Tone::kHuePreserving}},
                                  &o->tone));
    if (const toml::node* n = r.Take("aovs")) {
        const toml::array* a = n->as_array();
        if (a == nullptr) return r.TypeError("aovs", *n, "an array of strings");
        for (const toml::node& e : *a) {
            std::optional<std::string> s = e.value<std::string>();
            if (!s) return r.TypeError("aovs", *n, "an array of strings");
            if (*s == "albedo") {
                o->aov_albedo = true;
            } else if (*s == "normal") {
                o->aov_normal = true;
            } else if (*s == "depth") {
                o->aov_depth = true;
            } else {
                return r.RangeError("aovs", *n,
                                    fmt::format("'{}' is not an AOV (albedo, normal, depth)", *s));
            }
        }
    }
    return r.Finish();
}

}  // namespace

StatusOr<DateTime> ParseDateTime(std::string_view text) {
    // The sun model's ISO 8601 parser (render/scene/sun/spa.h) checks fields and requires a zone.
    NAVE_ASSIGN_OR_RETURN(CivilTime t, ParseIso8601(text));
    if (t.day > DaysInMonth(t.year, t.month)) {
        return InvalidArgumentError("'{}': day {} is not in 1..{} for {:04d}-{:02d}", text, t.day,
                                    DaysInMonth(t.year, t.month), t.year, t.month);
    }
    return DateTime{t.year,
                    t.month,
                    t.day,
                    t.hour,
                    t.minute,
                    t.second,
                    int(std::lround(t.utc_offset_hours * 60))};
}

StatusOr<SceneConfig> ParseSceneConfig(std::string_view text, const std::string& name) {
    toml::table root;
    try {
        root = toml::parse(text, name);
    } catch (const toml::parse_error& e) {
        return InvalidArgumentError("{}: {}", Where(name, e.source()), e.description());
    }
    SceneConfig config;
    config.path = name;
    TableReader r(root, "", name);
    NAVE_ASSIGN_OR_RETURN(const toml::table* camera, r.Table("camera"));
    if (camera == nullptr) return InvalidArgumentError("{}: missing [camera]", name);
    {
        TableReader t(*camera, "camera", name);
        NAVE_RETURN_IF_ERROR(ParseCamera(t, &config.camera));
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* sun, r.Table("sun"));
    if (sun != nullptr) {
        TableReader t(*sun, "sun", name);
        NAVE_RETURN_IF_ERROR(ParseSun(t, &config.sun));
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* sky, r.Table("sky"));
    if (sky != nullptr) {
        TableReader t(*sky, "sky", name);
        NAVE_RETURN_IF_ERROR(ParseSky(t, &config.sky));
    }
    if (const toml::node* lights = r.Take("lights")) {
        const toml::array* a = lights->as_array();
        if (a == nullptr) return r.TypeError("lights", *lights, "an array of tables ([[lights]])");
        for (size_t i = 0; i < a->size(); ++i) {
            const toml::table* lt = (*a)[i].as_table();
            if (lt == nullptr) return r.TypeError("lights", (*a)[i], "a table");
            TableReader t(*lt, fmt::format("lights[{}]", i), name);
            LightConfig l;
            NAVE_RETURN_IF_ERROR(ParseLight(t, &l));
            config.lights.push_back(std::move(l));
        }
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* medium, r.Table("medium"));
    if (medium != nullptr) {
        TableReader t(*medium, "medium", name);
        MediumConfig m;
        NAVE_RETURN_IF_ERROR(ParseMedium(t, &m));
        config.medium = std::move(m);
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* materials, r.Table("materials"));
    if (materials != nullptr) {
        for (auto&& [k, v] : *materials) {
            std::string key(k.str());
            if (!v.is_table()) {
                return InvalidArgumentError("{}: materials.{}: expected a table, found {}",
                                            Where(name, v.source()), key, TypeName(v));
            }
            TableReader t(*v.as_table(), "materials." + key, name);
            MaterialConfig m;
            NAVE_RETURN_IF_ERROR(ParseMaterial(t, &m));
            config.materials[key] = std::move(m);
        }
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* render, r.Table("render"));
    if (render != nullptr) {
        TableReader t(*render, "render", name);
        NAVE_RETURN_IF_ERROR(ParseRender(t, &config.render));
    }
    if (config.sky.kind == SkyConfig::Kind::kPreetham && !config.sun.enabled) {
        return InvalidArgumentError(
            "{}: sky.type = \"preetham\" needs an enabled [sun] (the sky follows it)", name);
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* output, r.Table("output"));
    if (output != nullptr) {
        TableReader t(*output, "output", name);
        NAVE_RETURN_IF_ERROR(ParseOutput(t, &config.output));
    }
    NAVE_ASSIGN_OR_RETURN(const toml::table* textures, r.Table("textures"));
    if (textures != nullptr) {
        TableReader t(*textures, "textures", name);
        NAVE_RETURN_IF_ERROR(ParseTextures(t, &config.textures));
    }
    NAVE_RETURN_IF_ERROR(r.Finish());
    return config;
}

StatusOr<SceneConfig> LoadSceneConfig(const std::filesystem::path& path) {
    NAVE_ASSIGN_OR_RETURN(std::string text, ReadFileToString(path));
    return ParseSceneConfig(text, path.string());
}

}  // namespace nave::render
