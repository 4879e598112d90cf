// SPDX-License-Identifier: Apache-2.0
#include "env/light_spec.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "env/spec_values.h"

namespace cambium::env {
namespace {

constexpr const char* program = "QuasiMC";

std::string lower(std::string s)
{
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

/// A side's optics from `r spec t tpow Nt`: QuasiMC's clamps, said rather than silent.
LeafOptics read_optics(const SpecLine& line)
{
    const std::vector<double> v = numbers_value(line, 3);
    LeafOptics o{v[0], v[2]};
    if (o.reflectance < 0 || o.reflectance > 1 || o.transmittance < 0 || o.transmittance > 1)
        throw Error(line.loc, std::string(program) + ": " + line.keyword +
                                  ": reflectance and transmittance lie in 0 .. 1, found '" + line.value + "'");
    if (o.reflectance + o.transmittance > 1) {
        warn(line.loc, std::string(program) + ": " + line.keyword +
                           ": reflectance and transmittance sum past 1; transmittance taken as 1 - reflectance");
        o.transmittance = 1 - o.reflectance;
    }
    return o;
}

LightAnswer read_answer(const SpecLine& line)
{
    const std::vector<std::string> tokens = value_tokens(line);
    const std::string first = tokens.empty() ? "" : tokens.front();
    if (first == "F")
        return LightAnswer::absorbed_flux;
    if (first == "D")
        return LightAnswer::absorbed_irradiance;
    if (first == "U")
        return LightAnswer::front_irradiance;
    if (first == "L")
        return LightAnswer::back_irradiance;
    throw Error(line.loc, std::string(program) + ": return type: F (absorbed flux), D (absorbed irradiance), "
                                                 "U or L (irradiance on the upper or lower side), found '" +
                              line.value + "'");
}

/// Keywords about QuasiMC's own sampling, output or display: no effect on the answers.
bool about_quasimc_itself(const std::string& k)
{
    static const char* const words[] = {"verbose",        "remove objects",   "number of runs",
                                        "sampling method", "russian roulette", "grid size",
                                        "one ray per spectrum", "cylinder sides", "visualization",
                                        "output file",    "return variance",  "source spectrum"};
    return std::any_of(std::begin(words), std::end(words), [&](const char* w) { return k == w; });
}

}  // namespace

bool names_light_environment(const std::string& program_path)
{
    return lower(std::filesystem::path(program_path).filename().string()) == "quasimc";
}

LightSpec read_light_spec(const std::vector<std::string>& args, const Context& context)
{
    LightSpec spec;
    bool lights_given = false, top_given = false;
    LeafOptics top{0.25, 0.25}, bottom{};  // QuasiMC's default leaf
    std::optional<LeafOptics> bottom_given;
    for (const SpecLine& line : read_spec_file(spec_argument(program, args), context)) {
        const std::string k = lower(line.keyword);
        if (k == "light source") {
            const std::vector<double> v = numbers_value(line, 4);  // x y z weight
            const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (!(length > 0) || v[3] < 0)
                throw Error(line.loc, std::string(program) +
                                          ": light source: a direction (not 0 0 0) and a weight of at least 0, found '" +
                                          line.value + "'");
            if (!lights_given)
                spec.lights.clear();
            lights_given = true;
            spec.lights.push_back(ParallelLight{{v[0] / length, v[1] / length, v[2] / length}, v[3]});
        } else if (k == "number of rays") {
            const double n = number_value(line);
            if (!(n >= 1 && n <= static_cast<double>(max_light_rays)))
                throw Error(line.loc, std::string(program) + ": number of rays: from 1 to " +
                                          std::to_string(max_light_rays) + ", found '" + line.value + "'");
            spec.rays = static_cast<std::uint64_t>(n);
        } else if (k == "maximum depth") {
            const double d = number_value(line);
            if (!(d >= 0 && d <= 4096))
                throw Error(line.loc, std::string(program) + ": maximum depth: from 0 to 4096, found '" +
                                          line.value + "'");
            spec.max_depth = static_cast<int>(d);
        } else if (k == "leaf material (top)") {
            top = read_optics(line);
            top_given = true;
        } else if (k == "leaf material (bottom)") {
            bottom_given = read_optics(line);
        } else if (k == "return type") {
            spec.answer = read_answer(line);
        } else if (k == "local light model") {
            if (!switch_value(line, {"Lambertian"}))
                warn(line.loc, std::string(program) + ": local light model: Cambium scatters diffusely (Lambertian); '" +
                                   line.value + "' ignored");
        } else if (k == "spectrum samples") {
            if (number_value(line) != 1)
                warn(line.loc, std::string(program) + ": spectrum samples: Cambium traces one band; '" + line.value +
                                   "' ignored");
        } else if (about_quasimc_itself(k)) {
            continue;
        } else {
            // material, rays from objects, ignore direct light, the sky model and files
            warn(FileLoc{line.loc.file, line.loc.line, 1},
                 std::string(program) + ": '" + line.keyword + "' is not followed by Cambium's light environment; ignored");
        }
    }
    if (top_given || bottom_given) {
        bottom = bottom_given.value_or(top);
        spec.optics = std::array<LeafOptics, 2>{top, bottom};
    }
    return spec;
}

}  // namespace cambium::env
