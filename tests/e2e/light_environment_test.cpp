// SPDX-License-Identifier: Apache-2.0
// The light environment (QuasiMC's `.e` line, docs/environment.md): each ?E is answered
// with the light its organ absorbs, traced on the plant's own geometry in one process.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "lsys/module_string.h"
#include "model_folder.h"

using namespace cambium;

namespace {

constexpr double pi = std::numbers::pi;

/// A one-step open L-system whose axiom is `axiom`, with QuasiMC named in its `.e` file
/// and `spec` as its specification; the derived string.
std::string derived(const std::string& name, const std::string& axiom, const std::string& spec, int threads = 0,
                    const std::string& productions = "")
{
    app::Options o = cambium::testing::write_model(
        "light_env_" + name,
        "Lsystem: 1\nderivation length: 1\nAxiom: " + axiom + "\n" + productions + "endlsystem\n");
    const auto folder = o.lsystem.parent_path();
    std::ofstream(folder / "plant.e") << "executable: QuasiMC -e plant.e light.spec\n"
                                         "following module: yes\n";
    std::ofstream(folder / "light.spec") << spec;
    o.environment_file = folder / "plant.e";
    o.quiet = true;
    o.threads = threads;
    app::Model model = app::load_model(o);
    return lsys::to_text(app::derive(model, o), model.lsystem.symbols());
}

/// The first parameters of the string's ?E modules, in order.
std::vector<double> answers(const std::string& string)
{
    std::vector<double> out;
    const std::regex e(R"(\?E\(([-0-9.e+]+))");
    for (auto it = std::sregex_iterator(string.begin(), string.end(), e); it != std::sregex_iterator(); ++it)
        out.push_back(std::stod((*it)[1]));
    return out;
}

// black leaves under one light straight down, of irradiance 2
const std::string black_sun = "light source: 0 -1 0 2\nleaf material (top): 0 10 0 10 1\nnumber of rays: 200000\n";

TEST(LightEnvironment, ABlackSphereAbsorbsItsShadowTimesTheIrradiance)
{
    // a sphere of diameter 2 casts a shadow of area pi
    const std::vector<double> a = answers(derived("sphere", "?E(0)@O(2)", black_sun));
    ASSERT_EQ(a.size(), 1u);
    EXPECT_NEAR(a[0], 2 * pi, 2 * pi * 0.005);
}

TEST(LightEnvironment, AnOrganIsEverythingItsHomomorphismDraws)
{
    // L draws two spheres side by side: both belong to the organ after the ?E
    const std::vector<double> a = answers(derived("homomorphism", "?E(0)L", black_sun, 0,
                                                  "homomorphism\nL --> @O(2)+(90)f(3)@O(2)\n"));
    ASSERT_EQ(a.size(), 1u);
    EXPECT_NEAR(a[0], 4 * pi, 4 * pi * 0.005);
}

TEST(LightEnvironment, AnOrganInTheShadowOfAnotherGetsNothing)
{
    // the turtle heads up (+y): the second sphere lies 4 above the first and shades it
    const std::vector<double> a = answers(derived("shade", "?E(0)@O(2)f(4)?E(0)@O(2)", black_sun));
    ASSERT_EQ(a.size(), 2u);
    EXPECT_LT(a[0], 2 * pi * 0.01);
    EXPECT_NEAR(a[1], 2 * pi, 2 * pi * 0.005);
    // moved aside by one radius, the lower sphere is lit where the upper's shadow is not:
    // two discs of radius 1 at distance 1 overlap in 2 acos(1/2) - sqrt(3)/2
    const double overlap = 2 * std::acos(0.5) - std::sqrt(3.0) / 2;
    const std::vector<double> b =
        answers(derived("half_shade", "?E(0)@O(2)f(4)+(90)f(1)-(90)?E(0)@O(2)", black_sun));
    ASSERT_EQ(b.size(), 2u);
    EXPECT_NEAR(b[0], 2 * (pi - overlap), 2 * pi * 0.01);
}

TEST(LightEnvironment, ShadedBudsDoNotGrow)
{
    // two buds with a leaf each; a black ball 3 above the first leaf shades it
    const std::string s = derived("grow", "[B?E(0)@O(1)f(3)@O(2)]+(90)f(5)-(90)B?E(0)@O(1)", black_sun, 0,
                                  "B > ?E(l) : l > 0.1 --> F(1)B\n");
    EXPECT_EQ(s.find("[B?E("), 0u) << s;  // the shaded bud: still a bud
    EXPECT_NE(s.find("-(90)F(1)B?E("), std::string::npos) << s;
}

TEST(LightEnvironment, ReturnTypesDivideByTheOrgansArea)
{
    // the sphere's area is 4 pi: absorbed irradiance and the irradiance arriving on its
    // outside are both 2 pi / 4 pi
    const std::vector<double> d = answers(derived("absorbed_irradiance", "?E(0)@O(2)", black_sun + "return type: D\n"));
    const std::vector<double> u = answers(derived("upper_irradiance", "?E(0)@O(2)", black_sun + "return type: U\n"));
    ASSERT_EQ(d.size(), 1u);
    ASSERT_EQ(u.size(), 1u);
    EXPECT_NEAR(d[0], 0.5, 0.5 * 0.005);
    EXPECT_NEAR(u[0], 0.5, 0.5 * 0.005);
}

TEST(LightEnvironment, ReflectedLightIsNotAbsorbed)
{
    // a leaf that reflects 0.3 and transmits 0.2 absorbs half of what arrives on it (only
    // the one sphere: nothing sends the scattered light back)
    const std::vector<double> a = answers(derived(
        "grey", "?E(0)@O(2)", "light source: 0 -1 0 2\nleaf material (top): 0.3 10 0.2 10 1\nnumber of rays: 200000\n"));
    ASSERT_EQ(a.size(), 1u);
    EXPECT_NEAR(a[0], pi, pi * 0.01);
}

TEST(LightEnvironment, NegativeQueriesAreLeftAndTheQModuleSetsTheRays)
{
    // ?E(-1) keeps its value; ?E(0) before Q(n) sets the rays and gets no answer
    const std::string s = derived("settings", "?E(-1)@O(2)?E(0)Q(1000)f(4)?E(0)@O(2)", black_sun);
    const std::vector<double> a = answers(s);
    ASSERT_EQ(a.size(), 3u);
    EXPECT_EQ(a[0], -1);
    EXPECT_EQ(a[1], 0);
    EXPECT_NEAR(a[2], 2 * pi, 2 * pi * 0.05);
}

TEST(LightEnvironment, TheSameAnswersAtAnyThreadCount)
{
    const std::string axiom = "?E(0)@O(2)f(3)+(60)f(1)?E(0)@O(1.5)";
    const std::string spec = "light source: 1 -2 0.5 1\nnumber of rays: 5000\n";
    const std::string one = derived("threads_a", axiom, spec, 1);
    EXPECT_EQ(one, derived("threads_b", axiom, spec, 2));
    EXPECT_EQ(one, derived("threads_c", axiom, spec, 7));
    EXPECT_EQ(answers(one).size(), 2u);
}

TEST(LightEnvironment, BadSpecificationsNameTheirLine)
{
    try {
        derived("bad", "?E(0)@O(2)", "light source: 0 -1 0\n");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("light.spec:1"), std::string::npos) << e.what();
    }
    try {
        derived("bad_return", "?E(0)@O(2)", "return type: X\n");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("return type"), std::string::npos) << e.what();
    }
}

}  // namespace
