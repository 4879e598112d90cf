// SPDX-License-Identifier: Apache-2.0
// The communication specification file (manual 7.4.1) and the text protocol's rounding.
#include <gtest/gtest.h>

#include "env/comm_spec.h"
#include "env_fixture.h"

namespace cambium::env {
namespace {

CommSpec spec_of(const std::string& test, const std::string& text)
{
    Context c = testing::model_with(test, "plant.e", text);
    return read_comm_spec(c.folder / "plant.e");
}

TEST(CommSpec, ReadsTheChunkSizeAfterTheType)
{
    EXPECT_EQ(spec_of("chunk", "executable: x\ncommunication type: pipes 500\n").queries_per_chunk,
              500);
    EXPECT_EQ(spec_of("chunk0", "executable: x\ncommunication type: pipes -3\n").queries_per_chunk,
              0);
    EXPECT_EQ(spec_of("chunk1", "executable: x\ncommunication type: pipes\n").queries_per_chunk, 0);
}

TEST(CommSpec, ReadsEveryDocumentedCommand)
{
    CommSpec s = spec_of("all", "executable: honda81 -e plant.e density.spec\n"
                                "communication type: files\n"
                                "turtle position:P:%.4f %.4f %.0f\n"
                                "turtle heading: %g %g\n"
                                "turtle left: %e\n"
                                "turtle up: %.2f %.2f %.2f\n"
                                "turtle line width: %.3f\n"
                                "turtle scale factor: %g\n"
                                "following module: no\n"
                                "interpreted modules: F(1), L;A B(0) A(2)\n"
                                "verbose: on\n");
    EXPECT_EQ(s.executable, (std::vector<std::string>{"honda81", "density.spec"}));
    EXPECT_EQ(s.communication_type, "files");
    ASSERT_TRUE(s.position);
    EXPECT_EQ(s.position->format, "P:%.4f %.4f %.0f");
    EXPECT_EQ(s.position->conversions, 3);
    EXPECT_EQ(s.heading->conversions, 2);
    EXPECT_EQ(s.left->conversions, 1);
    EXPECT_TRUE(s.up && s.line_width && s.scale_factor);
    EXPECT_FALSE(s.following_module);
    EXPECT_FALSE(s.interpreted.all);
    // as vlab's library: a later entry for a module replaces an earlier one
    EXPECT_EQ(s.interpreted.modules,
              (std::vector<InterpretedModule>{{"F", 1}, {"L", std::nullopt}, {"B", 0}, {"A", 2}}));
    EXPECT_TRUE(s.interpreted.matches("F", 1));
    EXPECT_FALSE(s.interpreted.matches("F", 2));  // F(1): only with one parameter
    EXPECT_TRUE(s.interpreted.matches("L", 3));
    EXPECT_FALSE(s.interpreted.matches("A", 0));
    EXPECT_FALSE(s.interpreted.matches("G", 0));
    CommSpec all = spec_of("every", "executable: a\ninterpreted modules: all F(1)\n");
    EXPECT_TRUE(all.interpreted.all && all.interpreted.matches("G", 5));
    EXPECT_TRUE(s.verbose);
}

TEST(CommSpec, DefaultsAreCpfgs)
{
    CommSpec s = spec_of("defaults", "executable: ecosystem spec\n");
    EXPECT_TRUE(s.following_module);  // cpfg sends it unless told not to
    EXPECT_EQ(s.communication_type, "pipes");
    EXPECT_FALSE(s.position);
}

TEST(CommSpec, BadLinesNameFileLineAndColumn)
{
    auto message = [](const std::string& test, const std::string& text) {
        try {
            spec_of(test, text);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("unknown", "executable: a\nturtle speed: %f\n").find("plant.e:2:1"), std::string::npos);
    // a %s or %n would read memory printf was never given: refused at its column
    EXPECT_NE(message("string", "executable: a\nturtle position: P:%s\n").find("plant.e:2:20"),
              std::string::npos);
    EXPECT_NE(message("count", "executable: a\nturtle line width: %f %f\n").find("more conversions"),
              std::string::npos);
    EXPECT_NE(message("wide", "executable: a\nturtle position: %999f\n").find("two digits"),
              std::string::npos);
    EXPECT_NE(message("type", "executable: a\ncommunication type: carrier pigeon\n").find("plant.e:2:21"),
              std::string::npos);
    EXPECT_NE(message("none", "verbose: on\n").find("executable"), std::string::npos);
    // vlab's library tells at most six parameters apart
    EXPECT_NE(message("seven", "executable: a\ninterpreted modules: F, G(7)\n").find("plant.e:2:25"),
              std::string::npos);
    EXPECT_NE(message("long", "executable: a\ninterpreted modules: @O\n").find("plant.e:2:22"),
              std::string::npos);
}

TEST(CommSpec, ValuesTravelAsTheFormatPrintsThem)
{
    TurtleFormat f{"P:%.4f %.4f %.0f", 3};
    const double v[3] = {0.123456, -2.00004, 0.6};
    float out[3] = {9, 9, 9};
    ASSERT_EQ(send_through_format(f, v, 3, out), 3);
    EXPECT_EQ(out[0], 0.1235f);
    EXPECT_EQ(out[1], -2.0f);
    EXPECT_EQ(out[2], 1.0f);  // %.0f rounds z to a whole number
    // two conversions: the third value is not sent
    TurtleFormat two{"P:%.4f %.4f", 2};
    EXPECT_EQ(send_through_format(two, v, 3, out), 2);
    // 4 significant digits
    TurtleFormat g{"%.4g %.4g %.4g", 3};
    const double w[3] = {12.3456, 0.000123456, 98766};
    send_through_format(g, w, 3, out);
    EXPECT_EQ(out[0], 12.35f);
    EXPECT_EQ(out[1], 0.0001235f);
    EXPECT_EQ(out[2], 9.877e4f);
}

TEST(CommSpec, ParametersKeepSixSignificantDigits)
{
    EXPECT_EQ(through_g(1.0f / 3.0f), 0.333333f);
    EXPECT_EQ(through_g(123456789.0f), 1.23457e8f);
    EXPECT_EQ(through_g(2.0f), 2.0f);
}

}  // namespace
}  // namespace cambium::env
