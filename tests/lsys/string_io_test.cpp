// SPDX-License-Identifier: Apache-2.0
// cpfg's text and binary string formats: exact bytes, round trips, malformed input.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>

#include "base/diagnostics.h"
#include "lsys/string_io.h"
#include "test_util.h"

namespace cambium::lsys {
namespace {

ModuleString make(SymbolTable& symbols,
                  std::initializer_list<std::pair<const char*, std::vector<float>>> modules)
{
    ModuleString s;
    for (const auto& [name, params] : modules)
        s.append(symbols.intern(name), params);
    return s;
}

std::string text_of(const ModuleString& s, const SymbolTable& symbols)
{
    std::ostringstream out;
    write_string_text(s, symbols, out);
    return out.str();
}

TEST(StringIo, TextPrintsParametersWithPercentG)
{
    SymbolTable symbols;
    ModuleString s = make(symbols, {{"F", {2}}, {"+", {22.5f}}, {"A", {1.44407e-05f, -3}},
                                    {"[", {}}, {"@Gs", {}}, {"]", {}}});
    EXPECT_EQ(text_of(s, symbols), "F(2)+(22.5)A(1.44407e-05,-3)[@Gs]\n");
}

std::string printf_g(float value)
{
    char text[64];
    int n = std::snprintf(text, sizeof text, "%g", static_cast<double>(value));
    return std::string(text, static_cast<std::size_t>(n));
}

std::string formatted(float value)
{
    char text[max_parameter_chars];
    return std::string(text, format_parameter(text, value));
}

TEST(StringIo, ParametersArePrintedAsPrintfPercentGPrintsThem)
{
    // the edges of the whole-number shortcut, of %g's exponent form and of rounding
    for (float v : {0.0f, -0.0f, 1.0f, -7.0f, 999999.0f, 1e6f, -1e6f, 1234567.0f, 0.5f, 1e-4f,
                    9.99999e-5f, 123456.5f, 999999.5f, 0.1f, 1.0f / 3, 16777216.0f, 1e-38f,
                    -3.4028235e38f, 1.17549435e-38f, 1e-45f})
        EXPECT_EQ(formatted(v), printf_g(v)) << printf_g(v);
    for (float v : {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                    std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::quiet_NaN()})
        EXPECT_EQ(formatted(v), printf_g(v));
    // every kind of float: bit patterns spread over the whole range, and small fractions
    std::uint32_t bits = 12345;
    for (int i = 0; i < 200000; ++i) {
        bits = bits * 1664525u + 1013904223u;
        float v;
        std::memcpy(&v, &bits, sizeof v);
        ASSERT_EQ(formatted(v), printf_g(v)) << "bits " << bits;
        float fraction = static_cast<float>(i % 20000) / 64.0f - 100.0f;  // exact ties
        ASSERT_EQ(formatted(fraction), printf_g(fraction));
        // floats from 10^-5 to 10^7, where most parameters lie
        std::uint32_t near = 0x37000000u + bits % (0x4b000000u - 0x37000000u);
        std::memcpy(&v, &near, sizeof v);
        ASSERT_EQ(formatted(v), printf_g(v)) << "bits " << near;
        ASSERT_EQ(formatted(-v), printf_g(-v)) << "bits " << near;
    }
}

TEST(StringIo, TextBreaksBeforeACharacterOnceSeventyAreOnTheLine)
{
    SymbolTable symbols;
    ModuleString s;
    SymbolId f = symbols.intern("F");
    for (int i = 0; i < 71; ++i)
        s.append(f);
    EXPECT_EQ(text_of(s, symbols), std::string(70, 'F') + "\nF\n");
}

TEST(StringIo, TextDoesNotCountCommasAndSplitsMultiCharacterNames)
{
    SymbolTable symbols;
    // 60 F, then A(1,2,3): 'A' 61, '(' 62, digits 65, ')' 66 - commas not counted
    ModuleString s;
    SymbolId f = symbols.intern("F");
    for (int i = 0; i < 60; ++i)
        s.append(f);
    std::vector<float> p = {1, 2, 3};
    s.append(symbols.intern("A"), p);
    for (int i = 0; i < 3; ++i)
        s.append(f);  // to 69
    s.append(symbols.intern("@Ts"), std::vector<float>{1});  // '@' is the 70th character
    EXPECT_EQ(text_of(s, symbols), std::string(60, 'F') + "A(1,2,3)FFF@\nTs(1)\n");
}

TEST(StringIo, TextRoundTripRegroupsNames)
{
    SymbolTable symbols;
    ModuleString s = make(symbols, {{"@Gs", {}}, {"~l", {3}}, {"?P", {0, 0, 0}}, {"?", {2}},
                                    {"@o", {0.2f}}, {"$", {}}, {"F", {-1.5f}}});
    std::stringstream io;
    write_string_text(s, symbols, io);
    ModuleString back = read_string_text(io, symbols);
    EXPECT_EQ(to_text(back, symbols), "@Gs~l(3)?P(0,0,0)?(2)@o(0.2)$F(-1.5)");
    EXPECT_EQ(back.size(), 7u);
}

TEST(StringIo, TextReaderSkipsBlanksAndLineBreaks)
{
    SymbolTable symbols;
    std::istringstream in("F (1, 2)\n+\t(90)\r\n @\nGc(4)");
    ModuleString s = read_string_text(in, symbols);
    EXPECT_EQ(to_text(s, symbols), "F(1,2)+(90)@Gc(4)");
    EXPECT_EQ(s.size(), 3u);
}

TEST(StringIo, BinaryHasCpfgHeaderAndBytes)
{
    SymbolTable symbols;
    ModuleString s = make(symbols, {{"F", {1}}, {"+", {}}, {"A", {2, 3}}});
    std::ostringstream out;
    write_string_binary(s, symbols, out, 4);
    std::string expected = "L-system string:20 4\n";
    float one = 1, two = 2, three = 3;
    auto bytes = [](float v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    expected += "F(" + bytes(one) + ")+A(" + bytes(two) + "," + bytes(three) + ")";
    EXPECT_EQ(out.str(), expected);
}

TEST(StringIo, BinaryRoundTrip)
{
    SymbolTable symbols;
    ModuleString s = make(symbols, {{"@Tx", {1}}, {"F", {0.1f}}, {"[", {}}, {"~k", {}},
                                    {"?H", {0.5f, 0.25f, 1e-20f}}, {"]", {}}});
    std::stringstream io;
    write_string_binary(s, symbols, io, 7);
    int step = 0;
    ModuleString back = read_string_binary(io, symbols, "<test>", &step);
    EXPECT_EQ(step, 7);
    ASSERT_EQ(back.size(), s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
        EXPECT_EQ(back.symbol(i), s.symbol(i));
    ASSERT_EQ(back.param_total(), s.param_total());
    for (std::size_t i = 0; i < s.param_total(); ++i)
        EXPECT_EQ(back.param_data()[i], s.param_data()[i]);  // bit-exact floats
}

std::string text_error(const std::string& text)
{
    SymbolTable symbols;
    std::istringstream in(text);
    try {
        read_string_text(in, symbols, "s.str");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(StringIo, MalformedTextNamesThePlace)
{
    EXPECT_NE(text_error("FF(1,").find("s.str:1:"), std::string::npos);
    EXPECT_NE(text_error("F(x)").find("expected a number"), std::string::npos);
    EXPECT_NE(text_error("F\n\n(x)").find("s.str:3:2"), std::string::npos);
    EXPECT_NE(text_error("(F").find("s.str:1:1"), std::string::npos);
    EXPECT_EQ(text_error(",)F"), "");  // ',' and ')' are turtle modules
    EXPECT_NE(text_error("F(1;2)").find("expected ',' or ')'"), std::string::npos);
    std::string many = "F(";
    for (int i = 0; i < 300; ++i)
        many += "1,";
    EXPECT_NE(text_error(many + "1)").find("255"), std::string::npos);
}

TEST(StringIo, MalformedBinaryIsAnError)
{
    SymbolTable symbols;
    std::istringstream wrong("L-system strinX12 0\nFFFFFFFFFFFF");
    EXPECT_THROW(read_string_binary(wrong, symbols), Error);
    std::istringstream truncated("L-system string:100 0\nFF");
    EXPECT_THROW(read_string_binary(truncated, symbols), Error);
    std::istringstream inside("L-system string:4 0\nF(ab");
    EXPECT_THROW(read_string_binary(inside, symbols), Error);
}

TEST(StringIo, ModuleLimitStopsReading)
{
    SymbolTable symbols;
    std::istringstream in("FFFFFFFFFF");
    EXPECT_THROW(read_string_text(in, symbols, "s", StringReadLimits{5}), Error);
}

TEST(StringIo, FrameNames)
{
    EXPECT_EQ(format_frame_name("plant%03d.str", 7), "plant007.str");
    EXPECT_EQ(format_frame_name("f%d", 12), "f12");
    EXPECT_EQ(format_frame_name("a%%b%4x", 255), "a%b  ff");
    EXPECT_EQ(format_frame_name("plain.str", 3), "plain.str");
    EXPECT_TRUE(is_frame_pattern("p%02d.strb"));
    EXPECT_FALSE(is_frame_pattern("p%%.strb"));
    EXPECT_THROW(format_frame_name("x%s", 1), Error);
    EXPECT_THROW(format_frame_name("%d_%d", 1), Error);
    EXPECT_THROW(format_frame_name("x%", 1), Error);
    EXPECT_THROW(format_frame_name("x%999999d", 1), Error);
    EXPECT_THROW(format_frame_name("x%ld", 1), Error);
}

}  // namespace
}  // namespace cambium::lsys
