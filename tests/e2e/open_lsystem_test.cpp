// SPDX-License-Identifier: Apache-2.0
// Open L-systems (manual 7): the environmental step runs before each derivation step on
// the string as the turtle reads it, and the answers change the derivation.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "app/pipeline.h"
#include "base/diagnostics.h"
#include "lsys/module_string.h"
#include "model_folder.h"

using namespace cambium;

namespace {

/// The manual's L-system 3 (section 7.1) with honda81 answering 1 (free) or 0 (blocked):
/// only free ends branch again.
app::Options sierpinski(const std::string& name, const std::string& homomorphism = "")
{
    app::Options o = cambium::testing::write_model(
        "open_" + name, "#define STEPS 3\nLsystem: 1\nderivation length: STEPS\nAxiom: ?E(1)\n"
                        "?E(c) : c == 1 --> [+F/(180)?E(1)]F?E(1)\n" +
                            homomorphism + "endlsystem\n");
    const auto folder = o.lsystem.parent_path();
    std::ofstream(folder / "plant.v", std::ios::app) << "angle increment: 60\n";
    std::ofstream(folder / "plant.e") << "executable: honda81 density.spec\n"
                                         "communication type: files\n"
                                         "turtle position:P:%.4f %.4f %.0f\n";
    std::ofstream(folder / "density.spec") << "verbose: off\nradius: 0.01\n3d case: on\n";
    o.environment_file = folder / "plant.e";
    o.quiet = true;
    return o;
}

std::string derived(const app::Options& options)
{
    app::Model model = app::load_model(options);
    return lsys::to_text(app::derive(model, options), model.lsystem.symbols());
}

TEST(OpenLSystem, CollidingEndsStopGrowing)
{
    // Step 2's string has two ends at one point (the manual's addresses 8 and 18): the
    // environment blocks both before step 3, so only the other two branch.
    EXPECT_EQ(derived(sierpinski("collide")),
              "[+F/(180)[+F/(180)?E(0)]F[+F/(180)?E(1)]F?E(1)]F[+F/(180)?E(0)]F[+F/(180)?E(1)]F?E(1)");
}

TEST(OpenLSystem, WithoutAnEnvironmentEveryEndGrows)
{
    app::Options options = sierpinski("closed");
    options.environment_file.reset();
    Diagnostics quiet(Diagnostics::Output::quiet);
    ScopedDiagnostics scope(quiet);
    const std::string s = derived(options);
    EXPECT_EQ(std::count(s.begin(), s.end(), 'E'), 8);
    EXPECT_EQ(s.find("?E(0)"), std::string::npos);
}

TEST(OpenLSystem, AnswersToModulesTheHomomorphismMakesAreDropped)
{
    // The homomorphism draws each ?E as a ?E of its own behind an F: the turtle then finds
    // ends at other points, but nothing it answers reaches the string.
    app::Options options = sierpinski("homomorphism", "homomorphism\n?E(c) --> F?E(c)\n");
    EXPECT_EQ(derived(options).find("?E(0)"), std::string::npos);
}

TEST(OpenLSystem, AProgramThatIsNotBuiltInIsRefusedBeforeAnyWork)
{
    app::Options options = sierpinski("external");
    std::ofstream(options.environment_file->c_str()) << "executable: ./obcheck obstacles.dat\n";
    try {
        app::load_model(options);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("plant.e:1:13"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("obcheck"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("--allow-environment-program"), std::string::npos);
    }
}

/// `?E(0,0) X` derived once with the protocol test program answering ?E(polygons, top):
/// the number of polygons sent after the ?E and their highest y.
std::string polygons_sent(const std::string& name, const std::string& interpreted,
                          const std::string& homomorphism)
{
    app::Options o = cambium::testing::write_model(
        "open_polygons_" + name, "Lsystem: 1\nderivation length: 1\nAxiom: ?E(0,0)X(2)\n"
                                 "?E(n,t) --> ?E(n,t)\nhomomorphism\n" +
                                     homomorphism + "endlsystem\n");
    const auto folder = o.lsystem.parent_path();
    std::ofstream(folder / "plant.e") << "executable: " << CAMBIUM_TEST_PROGRAM
                                      << " polygons\nturtle position:P:%g %g %g\n"
                                      << interpreted;
    o.environment_file = folder / "plant.e";
    o.allow_environment_program = true;
    o.quiet = true;
    return derived(o);
}

TEST(OpenLSystem, InterpretedModulesSendTheirPolygons)
{
    // X(2) drawn as a cylinder of length 2 up the turtle's heading (+y): the wall of
    // eight sides (geom::gls_tessellation), two triangles each, reaches y = 2
    const std::string cylinder = "X(l) --> F(l)\n";
    EXPECT_EQ(polygons_sent("named", "interpreted modules: X(1)\n", cylinder), "?E(16,2)X(2)");
    EXPECT_EQ(polygons_sent("all", "interpreted modules: all\n", cylinder), "?E(16,2)X(2)");
    // the whole homomorphism successor of the module is sent, not only its first module
    EXPECT_EQ(polygons_sent("successor", "interpreted modules: X\n", "X(l) --> F(l)F(l)\n"),
              "?E(32,4)X(2)");
    // a module the .e does not name (here: another parameter count) sends no block
    EXPECT_EQ(polygons_sent("other", "interpreted modules: X(2)\n", cylinder), "?E(0,0)X(2)");
    EXPECT_EQ(polygons_sent("none", "", cylinder), "?E(0,0)X(2)");
}

}  // namespace
