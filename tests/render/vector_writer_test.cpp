// SPDX-License-Identifier: Apache-2.0
// The vector files (render/vector_writer.h) read back as text: SVG's paths, PostScript's
// header and bounding box, PDF's header and one page of the window's size.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <unistd.h>

#include "base/diagnostics.h"
#include "render/vector_writer.h"

namespace cambium::render {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name)
{
    fs::path dir = fs::temp_directory_path() /
                   ("cambium_vector_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string bytes_of(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

/// A 300 x 200 window: a red and a blue triangle and a green line three pixels wide.
VectorDrawing two_triangles_and_a_line()
{
    VectorDrawing d;
    d.width = 300;
    d.height = 200;
    d.background = {1, 1, 1};
    VectorShape a;
    a.points = {PixelPoint{10, 20}, PixelPoint{110.5, 20}, PixelPoint{10, 180}};
    a.colour = {1, 0, 0};
    VectorShape b;
    b.points = {PixelPoint{150, 150}, PixelPoint{290, 10}, PixelPoint{290, 190}};
    b.colour = {0, 0, 1};
    VectorShape line;
    line.kind = VectorShape::Kind::line;
    line.points = {PixelPoint{5, 5}, PixelPoint{295, 195}, PixelPoint{}};
    line.colour = {0, 1, 0};
    line.line_width = 3;
    d.shapes = {a, b, line};
    return d;
}

TEST(VectorWriter, SvgHoldsOneFilledPathPerTriangleAtItsPoints)
{
    const fs::path dir = scratch("svg");
    const VectorDrawing d = two_triangles_and_a_line();
    write_vector(d, dir / "t.svg", VectorFormat::svg);
    const std::string svg = bytes_of(dir / "t.svg");
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("viewBox=\"0 0 300 200\""), std::string::npos) << svg;
    // filled paths, in the drawing's order, each starting at its triangle's points
    const std::regex path("<path style=\"([^\"]*)\" d=\"([^\"]*)\"");
    std::vector<std::pair<std::string, std::string>> filled, stroked;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), path); it != std::sregex_iterator(); ++it)
        ((*it)[1].str().find("fill:none") == std::string::npos ? filled : stroked)
            .push_back({(*it)[1].str(), (*it)[2].str()});
    ASSERT_EQ(filled.size(), 2u) << svg;
    ASSERT_EQ(stroked.size(), 1u) << svg;
    EXPECT_EQ(filled[0].second.rfind("M 10 20 L 110.5 20 L 10 180 Z", 0), 0u) << filled[0].second;
    EXPECT_NE(filled[0].first.find("fill:rgb(100%,0%,0%)"), std::string::npos);
    EXPECT_EQ(filled[1].second.rfind("M 150 150 L 290 10 L 290 190 Z", 0), 0u) << filled[1].second;
    EXPECT_NE(filled[1].first.find("fill:rgb(0%,0%,100%)"), std::string::npos);
    EXPECT_EQ(stroked[0].second.rfind("M 5 5 L 295 195", 0), 0u);
    EXPECT_NE(stroked[0].first.find("stroke-width:3"), std::string::npos);
    // the background fills the page
    EXPECT_NE(svg.find("width=\"300\" height=\"200\" style=\"fill:rgb(100%,100%,100%)"),
              std::string::npos) << svg;
    fs::remove_all(dir);
}

TEST(VectorWriter, PostScriptPageIsTheWindow)
{
    const fs::path dir = scratch("ps");
    write_vector(two_triangles_and_a_line(), dir / "t.ps", VectorFormat::ps);
    const std::string ps = bytes_of(dir / "t.ps");
    EXPECT_EQ(ps.rfind("%!PS", 0), 0u);
    EXPECT_NE(ps.find("\n%%BoundingBox: 0 0 300 200\n"), std::string::npos) << ps.substr(0, 400);
    EXPECT_NE(ps.find("\n%%Pages: 1\n"), std::string::npos);
    EXPECT_NE(ps.find("%%EOF"), std::string::npos);
    fs::remove_all(dir);
}

TEST(VectorWriter, PdfHasOnePageOfTheWindowsSize)
{
    const fs::path dir = scratch("pdf");
    write_vector(two_triangles_and_a_line(), dir / "t.pdf", VectorFormat::pdf);
    const std::string pdf = bytes_of(dir / "t.pdf");
    EXPECT_EQ(pdf.rfind("%PDF-", 0), 0u);
    const std::regex media("/MediaBox \\[ *([0-9.]+) +([0-9.]+) +([0-9.]+) +([0-9.]+) *\\]");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(pdf, m, media));
    EXPECT_EQ(std::stod(m[3]), 300);
    EXPECT_EQ(std::stod(m[4]), 200);
    const std::regex count("/Type /Pages[^>]*/Count ([0-9]+)");
    ASSERT_TRUE(std::regex_search(pdf, m, count));
    EXPECT_EQ(m[1], "1");
    EXPECT_NE(pdf.find("%%EOF"), std::string::npos);
    fs::remove_all(dir);
}

// A file that cannot be written leaves nothing behind and names itself; a file that was
// there before is kept as it was.
TEST(VectorWriter, FailureLeavesNothingBehind)
{
    const fs::path dir = scratch("fail");
    try {
        write_vector(two_triangles_and_a_line(), dir / "missing" / "t.svg", VectorFormat::svg);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("t.svg"), std::string::npos) << e.what();
    }
    VectorDrawing empty;
    std::ofstream(dir / "old.pdf") << "before";
    EXPECT_THROW(write_vector(empty, dir / "old.pdf", VectorFormat::pdf), Error);
    EXPECT_EQ(bytes_of(dir / "old.pdf"), "before");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace cambium::render
