// SPDX-License-Identifier: Apache-2.0
// The cambium command as a user runs it: exit status, messages, output files.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <sys/stat.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <iterator>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <sys/wait.h>

#include "shell_output.h"

namespace fs = std::filesystem;

namespace {

using Result = cambium::test::CommandResult;

/// Runs cambium with `args` (in `folder` when given).
Result run(const std::string& args, const fs::path& folder = {})
{
    return cambium::test::run_shell(std::string(CAMBIUM_EXE) + " " + args, folder);
}

fs::path scratch(const std::string& name)
{
    // The process id keeps concurrent runs of the suite (other checkouts) apart.
    fs::path dir = fs::temp_directory_path() /
                   ("cambium_cmd_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

/// `pattern` (one %02d-like field) with n in it.
std::string fmt_number(const char* pattern, int n)
{
    std::array<char, 64> name{};
    std::snprintf(name.data(), name.size(), pattern, n);
    return name.data();
}

/// An image file read back: its channel names and pixels as floats (0 .. 1 for 8-bit).
struct Picture {
    int width = 0, height = 0, channels = 0;
    std::vector<std::string> names;
    std::vector<float> pixels;

    float at(int x, int y, int c) const
    {
        return pixels[(std::size_t(y) * width + x) * channels + c];
    }
    int channel(const std::string& name) const
    {
        auto it = std::find(names.begin(), names.end(), name);
        return it == names.end() ? -1 : int(it - names.begin());
    }
};

Picture read_picture(const fs::path& file)
{
    Picture p;
    auto in = OIIO::ImageInput::open(file.string());
    if (!in)
        return p;
    const OIIO::ImageSpec& spec = in->spec();
    p.width = spec.width;
    p.height = spec.height;
    p.channels = spec.nchannels;
    p.names = spec.channelnames;
    p.pixels.resize(std::size_t(p.width) * p.height * p.channels);
    if (!in->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::FLOAT, p.pixels.data()))
        p.pixels.clear();
    return p;
}

/// Mean absolute difference of the RGB of two pictures of the same size.
double rgb_difference(const Picture& a, const Picture& b)
{
    double sum = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c)
                sum += std::fabs(a.at(x, y, c) - b.at(x, y, c));
    return sum / (3.0 * a.width * a.height);
}

}  // namespace

// --help names the program and its two forms of files, and lists each option once.
TEST(Command, HelpShowsHowTheCommandIsCalled)
{
    Result r = run("--help");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("Usage: cambium [OPTIONS] plant.l plant.v [plant.a]\n"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("cambium [OPTIONS] scene.json"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("(2x)"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("x 2 REQUIRED"), std::string::npos) << r.output;
    // every option line's flags once ("  -o TEXT ...", "  --spp INT ...")
    std::istringstream lines(r.output);
    std::map<std::string, int> seen;
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("  -", 0) == 0)
            ++seen[line.substr(2, line.find(' ', 2) - 2)];
    EXPECT_GT(seen.size(), 20u);
    for (const auto& [flag, count] : seen)
        EXPECT_EQ(count, 1) << flag;
}

TEST(Command, RendersAPlantToPngAndExr)
{
    fs::path dir = scratch("ok");
    write(dir / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nF --> F[+F]F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\ninitial line width: 0.2\n");
    Result r = run("-q -w 32 24 --spp 2 -o " + (dir / "p.png").string() + " -o " +
                   (dir / "p.exr").string() + " " + (dir / "p.l").string() + " " +
                   (dir / "p.v").string());
    EXPECT_EQ(r.status, 0) << r.output;
    Picture png = read_picture(dir / "p.png"), exr = read_picture(dir / "p.exr");
    ASSERT_EQ(png.width, 32);
    ASSERT_EQ(png.height, 24);
    ASSERT_EQ(exr.width, 32);
    ASSERT_FALSE(exr.pixels.empty());
    // The EXR holds linear RGBA and the albedo, normal and depth layers.
    for (const char* name : {"R", "G", "B", "A", "albedo.R", "albedo.G", "albedo.B",
                             "normal.X", "normal.Y", "normal.Z", "Z"})
        EXPECT_GE(exr.channel(name), 0) << name;
    // The plant covers some pixels, not all; where it does, the layers say so (a normal,
    // a finite depth, some albedo) and the PNG differs from the background.
    int a = exr.channel("A"), z = exr.channel("Z"), nx = exr.channel("normal.X");
    int covered = 0, differ = 0;
    float background[3] = {png.at(0, 0, 0), png.at(0, 0, 1), png.at(0, 0, 2)};
    for (int y = 0; y < exr.height; ++y)
        for (int x = 0; x < exr.width; ++x) {
            if (exr.at(x, y, a) < 1)
                continue;
            ++covered;
            EXPECT_TRUE(std::isfinite(exr.at(x, y, z))) << x << "," << y;
            double n2 = 0;
            for (int c = 0; c < 3; ++c)
                n2 += exr.at(x, y, nx + c) * exr.at(x, y, nx + c);
            // The mean of the samples' unit normals: at most 1 long, near 1 on a smooth tube.
            EXPECT_LE(n2, 1.01) << x << "," << y;
            EXPECT_GT(n2, 0.5) << x << "," << y;
            EXPECT_GT(exr.at(x, y, exr.channel("albedo.G")), 0) << x << "," << y;
            bool same = true;
            for (int c = 0; c < 3; ++c)
                same = same && std::fabs(png.at(x, y, c) - background[c]) < 0.02f;
            differ += same ? 0 : 1;
        }
    EXPECT_GT(covered, 4);
    EXPECT_LT(covered, 32 * 24 / 2);
    EXPECT_GT(differ, covered / 2);
}

// --denoise: the EXR's RGBA is the denoised frame, the raw one the noisy layer beside the
// organ ids, which name the F modules that drew the plant (its provenance); the PNG is
// written from the denoised frame. A tile cannot be denoised: an error before rendering.
TEST(Command, DenoiseWritesTheRawFrameBesideTheDenoisedOne)
{
    fs::path dir = scratch("denoise");
    write(dir / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nF --> F[+F]F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\ninitial line width: 0.2\n");
    const std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    Result r = run("-q -w 48 36 --spp 4 --ground --denoise -o " + (dir / "p.png").string() +
                   " -o " + (dir / "p.exr").string() + " " + files);
    ASSERT_EQ(r.status, 0) << r.output;
    Picture exr = read_picture(dir / "p.exr");
    for (const char* name : {"R", "A", "noisy.R", "noisy.G", "noisy.B", "noisy.A", "variance.R",
                             "variance.albedo", "organ.id", "albedo.R", "normal.X", "Z"})
        EXPECT_GE(exr.channel(name), 0) << name;
    const int noisy = exr.channel("noisy.R"), organ = exr.channel("organ.id");
    ASSERT_GE(organ, 0);
    double differ = 0;
    for (int y = 0; y < exr.height; ++y)
        for (int x = 0; x < exr.width; ++x)
            for (int c = 0; c < 3; ++c)
                differ += std::fabs(exr.at(x, y, c) - exr.at(x, y, noisy + c));
    EXPECT_GT(differ, 0.01) << "the denoised frame equals the raw one";
    // The organ ids as stored (32-bit unsigned): module indices of the derived string
    // F[+F]F (0 .. 5) on the plant, the ground's or the background's elsewhere (the
    // parallel view sees the ground edge-on); none unknown (every cylinder has its module).
    auto in = OIIO::ImageInput::open((dir / "p.exr").string());
    ASSERT_TRUE(in);
    std::vector<std::uint32_t> ids(std::size_t(exr.width) * exr.height);
    ASSERT_TRUE(in->read_image(0, 0, organ, organ + 1, OIIO::TypeDesc::UINT, ids.data()));
    in->close();
    const auto plant = std::count_if(ids.begin(), ids.end(), [](std::uint32_t id) { return id < 6; });
    EXPECT_GT(plant, 4) << "no pixel names an F module";
    EXPECT_LT(plant, std::ptrdiff_t(ids.size() / 2));
    EXPECT_EQ(std::count(ids.begin(), ids.end(), 0xfffffffdu), 0) << "an unknown module";
    EXPECT_TRUE(fs::exists(dir / "p.png"));

    Result tile = run("-q -w 48 36 --spp 1 --denoise --tile 0/2 -o " + (dir / "t.png").string() +
                      " " + files);
    EXPECT_NE(tile.status, 0);
    EXPECT_NE(tile.output.find("--denoise needs the whole image"), std::string::npos) << tile.output;
}

// --organ-masks: the EXR gets Cryptomatte layers whose manifest names the visible F
// modules of F[+F]F by index and the symbol F, organ channels with the branched F's
// order 1 and every covered pixel's age known; without the option none of it, and
// without an EXR output, or split into tiles, an error before rendering.
TEST(Command, OrganMasksNameTheModulesInTheExr)
{
    fs::path dir = scratch("organ_masks");
    write(dir / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nF --> F[+F]F\nendlsystem\n");
    write(dir / "p.v", "angle increment: 45\nline style: cylinder\ninitial line width: 0.3\n");
    const std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    Result r = run("-q -w 48 36 --spp 4 --organ-masks -o " + (dir / "m.exr").string() + " " + files);
    ASSERT_EQ(r.status, 0) << r.output;
    Picture exr = read_picture(dir / "m.exr");
    for (const char* name : {"CryptoOrgan00.R", "CryptoOrgan02.A", "CryptoSymbol00.R", "CryptoSymbol02.A",
                             "organ.index", "organ.age", "organ.order", "organ.plant"})
        EXPECT_GE(exr.channel(name), 0) << name;
    auto in = OIIO::ImageInput::open((dir / "m.exr").string());
    ASSERT_TRUE(in);
    const std::string organs = in->spec().get_string_attribute("cryptomatte/e72bb61/manifest");
    const std::string symbols = in->spec().get_string_attribute("cryptomatte/0f85aed/manifest");
    in->close();
    for (const char* name : {"\"F 0\"", "\"F 3\"", "\"F 5\""})
        EXPECT_NE(organs.find(name), std::string::npos) << organs;
    EXPECT_EQ(symbols, "{\"F\":\"982b1106\"}");
    const int order = exr.channel("organ.order"), index = exr.channel("organ.index"),
              age = exr.channel("organ.age");
    int branched = 0;
    for (int y = 0; y < exr.height; ++y)
        for (int x = 0; x < exr.width; ++x) {
            if (exr.at(x, y, index) < 0)
                continue;
            EXPECT_GE(exr.at(x, y, age), 0) << x << "," << y;
            if (exr.at(x, y, index) == 3) {
                EXPECT_EQ(exr.at(x, y, order), 1) << x << "," << y;
                ++branched;
            } else {
                EXPECT_EQ(exr.at(x, y, order), 0) << x << "," << y;
            }
        }
    EXPECT_GT(branched, 0);

    r = run("-q -w 48 36 --spp 4 -o " + (dir / "plain.exr").string() + " " + files);
    ASSERT_EQ(r.status, 0) << r.output;
    Picture plain = read_picture(dir / "plain.exr");
    EXPECT_LT(plain.channel("CryptoOrgan00.R"), 0);
    EXPECT_LT(plain.channel("organ.index"), 0);

    Result png = run("-q -w 48 36 --organ-masks -o " + (dir / "m.png").string() + " " + files);
    EXPECT_NE(png.status, 0);
    EXPECT_NE(png.output.find("give an -o file.exr"), std::string::npos) << png.output;
    Result tile = run("-q -w 48 36 --organ-masks --tile 0/2 -o " + (dir / "t.exr").string() + " " + files);
    EXPECT_NE(tile.status, 0);
    EXPECT_NE(tile.output.find("--organ-masks needs the whole image"), std::string::npos) << tile.output;
}

// `render mode: wireframe` draws a polygon as its outline of 1-pixel lines in its colour
// (cpfg's grey without a colour file) and leaves the inside, diagonal included, to the
// background; `filled` fills it. The square spans most of the 64 x 64 image.
TEST(Command, WireframeSquareIsItsOutlineOfOnePixelLines)
{
    fs::path dir = scratch("wireframe");
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: {f+f+f+f}\nendlsystem\n");
    auto picture = [&](const std::string& mode) {
        write(dir / "p.v", "angle increment: 90\nscale factor: 0.8\nrender mode: " + mode + "\n");
        Result r = run("-q -w 64 64 --spp 4 -o " + (dir / "p.png").string() + " " + (dir / "p.l").string() +
                       " " + (dir / "p.v").string());
        EXPECT_EQ(r.status, 0) << r.output;
        return read_picture(dir / "p.png");
    };
    const float grey = 200 / 255.0f;
    Picture filled = picture("filled");
    ASSERT_EQ(filled.width, 64);
    EXPECT_NEAR(filled.at(32, 32, 0), grey, 0.01f);
    Picture wire = picture("wireframe");
    ASSERT_EQ(wire.width, 64);
    EXPECT_EQ(wire.at(32, 32, 0), 0.0f);  // the centre, on the diagonal
    EXPECT_EQ(wire.at(20, 40, 0), 0.0f);
    // Every column and row through the middle crosses two sides, one pixel each, grey.
    for (int i = 16; i < 48; ++i) {
        int column = 0, row = 0;
        for (int j = 0; j < 64; ++j) {
            for (auto [x, y, count] : {std::tuple{i, j, &column}, std::tuple{j, i, &row}})
                if (wire.at(x, y, 0) > 0) {
                    ++*count;
                    EXPECT_NEAR(wire.at(x, y, 0), grey, 0.01f) << x << "," << y;
                }
        }
        EXPECT_EQ(column, 2) << "column " << i;
        EXPECT_EQ(row, 2) << "row " << i;
    }
}

// The view file's texture images are read from the model's folder and below, as the
// L-system's own files are (docs/security.md): one elsewhere, through "..", an absolute
// path or a link, is refused with the view file named and nothing written, unless
// --allow-file-access. Cambium runs here from the model's parent folder: relative names
// are the view file's folder's, not the current folder's.
TEST(Command, TexturesStayInTheModelsFolderUnlessAllowed)
{
    fs::path dir = scratch("texture"), model = dir / "model";
    fs::create_directories(model / "maps");
    write(model / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nendlsystem\n");
    write(dir / "outside.png", "not looked at");
    write(model / "maps" / "inside.png", "not looked at");
    fs::create_symlink(dir / "outside.png", model / "link.png");
    auto render_with = [&](const std::string& texture, const std::string& options) {
        write(model / "p.v", "line style: cylinder\ntexture: F: " + texture + "\n");
        fs::remove(dir / "out.png");
        return run("-q -w 8 6 --spp 1 " + options + " -o out.png model/p.l model/p.v", dir);
    };
    const std::vector<std::string> outside_names{"../outside.png", (dir / "outside.png").string(),
                                                 "link.png", "maps/../../outside.png"};
    for (const std::string& outside : outside_names) {
        Result r = render_with(outside, "");
        EXPECT_NE(r.status, 0) << outside;
        EXPECT_NE(r.output.find("p.v: error: texture '"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("outside the model's folder"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(dir / "out.png")) << outside;
        Result allowed = render_with(outside, "--allow-file-access");
        EXPECT_EQ(allowed.status, 0) << outside << ": " << allowed.output;
        EXPECT_TRUE(fs::exists(dir / "out.png")) << outside;
    }
    for (const char* inside : {"maps/inside.png", "maps/../maps/inside.png"}) {
        Result r = render_with(inside, "");
        EXPECT_EQ(r.status, 0) << inside << ": " << r.output;
        EXPECT_TRUE(fs::exists(dir / "out.png")) << inside;
    }
}

// The other files a view file names (surfaces, contours, functions, background scenes)
// are confined like its textures: a name that reaches outside the model's folder,
// through "..", an absolute path or a link, is refused before anything is read, with
// the view file's line; --allow-file-access lifts it (the reader then fails on the
// stand-in file's contents instead).
TEST(Command, FilesAViewFileNamesStayInTheModelsFolder)
{
    fs::path dir = scratch("named-files"), model = dir / "model";
    fs::create_directories(model);
    write(model / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nendlsystem\n");
    write(dir / "outside.s", "not a surface");
    fs::create_symlink(dir / "outside.s", model / "link.s");
    auto render_with = [&](const std::string& command, const std::string& options) {
        write(model / "p.v", "line style: cylinder\n" + command + "\n");
        fs::remove(dir / "out.png");
        return run("-q -w 8 6 --spp 1 " + options + " -o out.png model/p.l model/p.v", dir);
    };
    for (const std::string& command :
         {std::string("surface: S ../outside.s 1"), "surface: S " + (dir / "outside.s").string() + " 1",
          std::string("surface: S link.s 1"), std::string("function: ../outside.s 20")}) {
        Result r = render_with(command, "");
        EXPECT_NE(r.status, 0) << command;
        EXPECT_NE(r.output.find("p.v:2"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("outside the model's folder"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(dir / "out.png")) << command;
        Result allowed = render_with(command, "--allow-file-access");
        EXPECT_EQ(allowed.output.find("outside the model's folder"), std::string::npos)
            << command << ": " << allowed.output;
    }
}

// Files included by the model's own files are confined too: an L-system's or a
// background scene's `#include` of a file outside the model's folder is an error naming
// the directive, and nothing is written; --allow-file-access lifts it.
TEST(Command, IncludesStayInTheModelsFolder)
{
    fs::path dir = scratch("includes"), model = dir / "model";
    fs::create_directories(model);
    write(dir / "steps.h", "#define STEPS 1\n");
    write(dir / "ground.h", "\n");
    write(model / "bg.dat", "#include \"../ground.h\"\n");
    auto render_with = [&](const std::string& lsystem, const std::string& view,
                           const std::string& options) {
        write(model / "p.l", lsystem);
        write(model / "p.v", "line style: cylinder\n" + view);
        fs::remove(dir / "out.png");
        return run("-q -w 8 6 --spp 1 " + options + " -o out.png model/p.l model/p.v", dir);
    };
    const std::string plain = "lsystem: 1\nderivation length: 1\naxiom: F\nendlsystem\n";
    const std::string including = "#include \"../steps.h\"\nlsystem: 1\nderivation length: STEPS\naxiom: F\nendlsystem\n";
    struct Case {
        std::string lsystem, view, where;
    };
    for (const Case& c : {Case{including, "", "p.l:1:1: error: #include names"},
                          Case{plain, "background scene: bg.dat\n", "bg.dat:1:1: error: #include names"}}) {
        Result r = render_with(c.lsystem, c.view, "");
        EXPECT_NE(r.status, 0) << c.where;
        EXPECT_NE(r.output.find(c.where), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("lies outside the model's folder"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(dir / "out.png")) << c.where;
        Result allowed = render_with(c.lsystem, c.view, "--allow-file-access");
        EXPECT_EQ(allowed.status, 0) << c.where << ": " << allowed.output;
        EXPECT_TRUE(fs::exists(dir / "out.png")) << c.where;
    }
}

TEST(Command, SyntaxErrorNamesFileLineAndColumnAndWritesNothing)
{
    fs::path dir = scratch("bad");
    write(dir / "bad.l", "lsystem: 1\nderivation length: 1\naxiom: F\nF -> F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\n");
    Result r = run("-o " + (dir / "out.png").string() + " " + (dir / "bad.l").string() + " " +
                   (dir / "p.v").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("bad.l:4:"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("error"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
}

TEST(Command, MissingViewFileIsAClearError)
{
    fs::path dir = scratch("missing");
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: F\nendlsystem\n");
    Result r = run((dir / "p.l").string() + " " + (dir / "nope.v").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("nope.v"), std::string::npos) << r.output;
}

TEST(Command, UnknownOutputFormatFailsBeforeRendering)
{
    fs::path dir = scratch("format");
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: F\nendlsystem\n");
    write(dir / "p.v", "\n");
    Result r = run("-o " + (dir / "p.xyz").string() + " " + (dir / "p.l").string() + " " +
                   (dir / "p.v").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("p.xyz"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("rendered"), std::string::npos) << r.output;
}

// cpfg's -rgb and -tga write the picture as SGI and Targa files: the PNG's pixels.
TEST(Command, CpfgsRgbAndTgaOutputsHoldThePicture)
{
    fs::path dir = scratch("rgb");
    write(dir / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nF --> F[+F]F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\ninitial line width: 0.2\n");
    Result r = run("-q -w 32 24 --spp 2 -rgb " + (dir / "p.rgb").string() + " -tga " +
                   (dir / "p.tga").string() + " -o " + (dir / "p.png").string() + " " +
                   (dir / "p.l").string() + " " + (dir / "p.v").string());
    ASSERT_EQ(r.status, 0) << r.output;
    Picture png = read_picture(dir / "p.png");
    for (const char* name : {"p.rgb", "p.tga"}) {
        Picture other = read_picture(dir / name);
        EXPECT_EQ(other.width, 32) << name;
        EXPECT_EQ(other.pixels, png.pixels) << name;
    }
    // no library here writes Sun raster files: said, and nothing written
    Result ras = run("-w 8 8 --spp 1 -ras " + (dir / "p.ras").string() + " -o " +
                     (dir / "q.png").string() + " " + (dir / "p.l").string() + " " +
                     (dir / "p.v").string());
    EXPECT_NE(ras.output.find("p.ras is not written"), std::string::npos) << ras.output;
    EXPECT_FALSE(fs::exists(dir / "p.ras"));
}

// --turbidity and --env-rotate are accepted with what they change, refused without it or
// out of range (the model's fit covers turbidity 1.7 .. 10).
TEST(Command, SkyTurbidityAndEnvironmentRotation)
{
    fs::path dir = scratch("sky");
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\ninitial line width: 0.2\n");
    std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    std::string out = " -q -w 16 12 --spp 1 -o " + (dir / "p.png").string() + " ";
    Result ok = run(out + "--sky --turbidity 6 --sun 1 1 0 --env-rotate 45 " + files);
    EXPECT_EQ(ok.status, 0) << ok.output;
    EXPECT_TRUE(fs::exists(dir / "p.png"));
    // Each option changes the image: a clear sky, then a hazy one, then the hazy one
    // turned (a perspective view sees the sky behind the plant).
    write(dir / "q.v", "projection: perspective\nviewing angle: 60\nline style: cylinder\n"
                       "initial line width: 0.2\n");
    std::string view = (dir / "p.l").string() + " " + (dir / "q.v").string();
    auto sky_png = [&](const std::string& name, const std::string& options) {
        Result r = run(" -q -w 16 12 --spp 4 -o " + (dir / name).string() + " " + options +
                       " " + view);
        EXPECT_EQ(r.status, 0) << r.output;
        return read_picture(dir / name);
    };
    Picture clear = sky_png("clear.png", "--sky --turbidity 2 --sun 1 1 0");
    Picture haze = sky_png("hazy.png", "--sky --turbidity 9 --sun 1 1 0");
    Picture turned = sky_png("turned.png", "--sky --turbidity 9 --sun 1 1 0 --env-rotate 90");
    Picture hazy_again = sky_png("hazy2.png", "--sky --turbidity 9 --sun 1 1 0");
    ASSERT_FALSE(clear.pixels.empty());
    ASSERT_FALSE(haze.pixels.empty());
    ASSERT_FALSE(turned.pixels.empty());
    EXPECT_EQ(rgb_difference(haze, hazy_again), 0);  // the same options: the same image
    EXPECT_GT(rgb_difference(clear, haze), 0.01);
    EXPECT_GT(rgb_difference(haze, turned), 0.01);

    Result lonely = run(out + "--turbidity 6 " + files);
    EXPECT_NE(lonely.status, 0);
    EXPECT_NE(lonely.output.find("--sky"), std::string::npos) << lonely.output;
    Result hazy = run(out + "--sky --turbidity 20 " + files);
    EXPECT_NE(hazy.status, 0);
    EXPECT_NE(hazy.output.find("turbidity"), std::string::npos) << hazy.output;
    Result turn = run(out + "--env-rotate 90 " + files);
    EXPECT_NE(turn.status, 0);
    EXPECT_NE(turn.output.find("--env-rotate"), std::string::npos) << turn.output;

    // `--background sky` brings the sky it shows: the same image as with --sky.
    Picture shown = sky_png("shown.png", "--background sky --turbidity 9 --sun 1 1 0");
    Picture given = sky_png("given.png", "--sky --background sky --turbidity 9 --sun 1 1 0");
    ASSERT_FALSE(shown.pixels.empty());
    EXPECT_EQ(rgb_difference(shown, given), 0);
    // --no-view-lights leaves out cpfg's default light (q.v has no light:): under the sky
    // the plant is lit by the sky alone, a different image; without the sky and with no
    // ambient the plant is black against the background.
    Picture skylit = sky_png("skylit.png", "--sky --turbidity 9 --sun 1 1 0 --no-view-lights");
    ASSERT_FALSE(skylit.pixels.empty());
    EXPECT_GT(rgb_difference(haze, skylit), 0.001);
    Picture with_light = sky_png("lamp.png", "--ambient 0 --background 1,1,1");
    Picture unlit = sky_png("unlit.png", "--ambient 0 --background 1,1,1 --no-view-lights");
    ASSERT_FALSE(unlit.pixels.empty());
    EXPECT_GT(rgb_difference(with_light, unlit), 0.01);
    int black = 0;
    for (int y = 0; y < unlit.height; ++y)
        for (int x = 0; x < unlit.width; ++x)
            black += unlit.at(x, y, 0) == 0 && unlit.at(x, y, 1) == 0 && unlit.at(x, y, 2) == 0;
    EXPECT_GT(black, 0);  // the plant's pixels
}

namespace {

const char* plant_l = "lsystem: 1\nderivation length: 1\naxiom: F\nF --> F[+F]F\nendlsystem\n";
const char* plant_v = "line style: cylinder\ninitial line width: 0.2\n";

std::string bytes_of(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

fs::path corpus_model(const std::string& id)
{
    const char* env = std::getenv("CAMBIUM_CORPUS");
    return fs::path(env ? env : CAMBIUM_CORPUS_DEFAULT) / "cpfg" / id;
}

}  // namespace

// As cpfg users run it, inside the model's folder: the background scene (two spheres,
// cylinders, a cone, polygons) is drawn.
TEST(Command, BackgroundSceneFromInsideTheModelFolder)
{
    fs::path model = corpus_model("10-manuals/11-CPFG/BackgroundScene");
    if (!fs::exists(model / "plant.v"))
        GTEST_SKIP() << "corpus not found";
    fs::path dir = scratch("background");
    // a tiny image: -vv alone walks the turtle without building geometry
    Result r = run("-M plant.mat plant.l plant.v -w 8 6 --spp 1 -o " + (dir / "p.png").string() +
                       " < /dev/null",
                   model);
    EXPECT_EQ(r.status, 0) << r.output;
    // the sphere under `scale 2 1 1` is an ellipsoid of triangles, as cpfg draws it
    EXPECT_NE(r.output.find("1 spheres"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("982 triangles"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
}

// Numbers out of range in options are clear errors before any work.
TEST(Command, BadNumbersInOptionsAreClearErrors)
{
    fs::path dir = scratch("numbers");
    write(dir / "p.l", plant_l);
    write(dir / "p.v", plant_v);
    std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    Result big = run("-m99999999999 " + (dir / "p.map").string() + " " + files);
    EXPECT_EQ(big.status, 1 << 8);
    EXPECT_NE(big.output.find("option -m99999999999: the colour map number: expected a whole "
                              "number from 0 to 15, not '99999999999'"),
              std::string::npos)
        << big.output;
    EXPECT_EQ(big.output.find("stoi"), std::string::npos) << big.output;
    Result block = run("-c123456789012 " + files);
    EXPECT_NE(block.output.find("option -c123456789012: the colour map number"), std::string::npos)
        << block.output;
    Result huge = run("-w 32768 32768 " + files);
    EXPECT_NE(huge.status, 0);
    EXPECT_NE(huge.output.find("-w: 32768 x 32768 is more than 67108864 pixels"),
              std::string::npos)
        << huge.output;
    EXPECT_EQ(huge.output.find("derived"), std::string::npos) << huge.output;  // before the work
    Result word = run("-w 64 sixty " + files);
    EXPECT_NE(word.output.find("-w: expected a whole number from 1 to 32768, not 'sixty'"),
              std::string::npos)
        << word.output;
    Result spp = run("--spp lots " + files);
    EXPECT_NE(spp.status, 0);
    EXPECT_NE(spp.output.find("--spp"), std::string::npos) << spp.output;
    Result seed = run("--seed -3 " + files);
    EXPECT_NE(seed.status, 0);
    EXPECT_NE(seed.output.find("--seed"), std::string::npos) << seed.output;
    EXPECT_EQ(seed.output.find("derived"), std::string::npos) << seed.output;
}

// A FIFO (or device) given as the L-system file is refused, not read forever.
TEST(Command, LsystemFileMustBeARegularFile)
{
    fs::path dir = scratch("fifo");
    write(dir / "p.v", plant_v);
    ASSERT_EQ(::mkfifo((dir / "p.l").c_str(), 0600), 0);
    Result r = run((dir / "p.l").string() + " " + (dir / "p.v").string() + " < /dev/null");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("p.l: error: cannot open the L-system file: not a regular file"),
              std::string::npos)
        << r.output;
}

// -q prints nothing but errors: warnings too.
TEST(Command, QuietSilencesWarnings)
{
    fs::path dir = scratch("quiet");
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: F@S(\"true\")\nendlsystem\n");
    write(dir / "p.v", plant_v);
    std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    Result loud = run("-vv " + (dir / "p.vv").string() + " " + files);
    EXPECT_NE(loud.output.find("warning: @S system calls are not run"), std::string::npos)
        << loud.output;
    Result quiet = run("-q -vv " + (dir / "p.vv").string() + " " + files);
    EXPECT_EQ(quiet.status, 0);
    EXPECT_EQ(quiet.output, "");
}

// @S runs its command only with --allow-system-calls, in the model's folder.
TEST(Command, SystemCallsRunOnlyWhenAllowed)
{
    fs::path dir = scratch("system");
    write(dir / "p.l",
          "lsystem: 1\nderivation length: 0\naxiom: F@S(\"pwd > ran.txt\")\nendlsystem\n");
    write(dir / "p.v", plant_v);
    std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    Result refused = run("-vv " + (dir / "p.vv").string() + " " + files);
    EXPECT_EQ(refused.status, 0) << refused.output;
    EXPECT_FALSE(fs::exists(dir / "ran.txt"));
    EXPECT_NE(refused.output.find("use --allow-system-calls"), std::string::npos);
    Result allowed = run("--allow-system-calls -vv " + (dir / "p.vv").string() + " " + files);
    EXPECT_EQ(allowed.status, 0) << allowed.output;
    EXPECT_EQ(bytes_of(dir / "ran.txt"), fs::canonical(dir).string() + "\n");
}

// Identical runs give identical files: no time stamps in EXR or TIFF headers.
TEST(Command, IdenticalRunsGiveIdenticalFiles)
{
    fs::path dir = scratch("identical");
    write(dir / "p.l", plant_l);
    write(dir / "p.v", plant_v);
    std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    for (const char* run_name : {"a", "b"}) {
        std::string outs;
        for (const char* ext : {".exr", ".png", ".tif"})
            outs += " -o " + (dir / (std::string(run_name) + ext)).string();
        Result r = run("-q -w 24 16 --spp 2" + outs + " " + files);
        ASSERT_EQ(r.status, 0) << r.output;
    }
    for (const char* ext : {".exr", ".png", ".tif"}) {
        std::string a = bytes_of(dir / (std::string("a") + ext));
        EXPECT_FALSE(a.empty());
        EXPECT_TRUE(a == bytes_of(dir / (std::string("b") + ext))) << ext;
        auto in = OIIO::ImageInput::open((dir / (std::string("a") + ext)).string());
        ASSERT_TRUE(in);
        EXPECT_EQ(in->spec().find_attribute("DateTime"), nullptr) << ext;
        EXPECT_EQ(in->spec().find_attribute("capDate"), nullptr) << ext;
    }
}

// PostScript and PDF: cairo dates them when written; Cambium dates them SOURCE_DATE_EPOCH
// (the epoch without it), so identical runs give identical bytes.
TEST(Command, IdenticalRunsGiveIdenticalDrawings)
{
    fs::path dir = scratch("identical_drawings");
    write(dir / "p.l", plant_l);
    write(dir / "p.v", plant_v);
    const std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    for (const char* run_name : {"a", "b"}) {
        Result r = run("-q -w 48 32 -ps " + (dir / (std::string(run_name) + ".ps")).string() +
                       " -o " + (dir / (std::string(run_name) + ".pdf")).string() + " " + files);
        ASSERT_EQ(r.status, 0) << r.output;
    }
    for (const char* ext : {".ps", ".pdf"}) {
        const std::string a = bytes_of(dir / (std::string("a") + ext));
        EXPECT_FALSE(a.empty());
        EXPECT_TRUE(a == bytes_of(dir / (std::string("b") + ext))) << ext;
    }
    // runs a second apart would differ without a fixed date: the date is the one given
    EXPECT_NE(bytes_of(dir / "a.ps").find("\n%%CreationDate: Thu Jan  1 00:00:00 1970\n"), std::string::npos);
    EXPECT_NE(bytes_of(dir / "a.pdf").find("/CreationDate (19700101000000Z)"), std::string::npos);
    Result epoch = cambium::test::run_shell("SOURCE_DATE_EPOCH=1700000000 " + std::string(CAMBIUM_EXE) +
                                            " -q -w 48 32 -ps c.ps -o c.pdf " + files, dir);
    ASSERT_EQ(epoch.status, 0) << epoch.output;
    const std::string ps = bytes_of(dir / "c.ps");
    EXPECT_NE(ps.find("\n%%CreationDate: Tue Nov 14 22:13:20 2023\n"), std::string::npos) << ps.substr(0, 200);
    EXPECT_NE(bytes_of(dir / "c.pdf").find("/CreationDate (20231114221320Z)"), std::string::npos);
    // the rest of the file is cairo's as it wrote it: only the date line differs
    EXPECT_EQ(ps.size(), bytes_of(dir / "a.ps").size());
}

// TIFF: no alpha when opaque; associated alpha when transparent, so readers that
// premultiply and readers that do not show the same picture.
TEST(Command, TiffAlphaIsAssociatedOrAbsent)
{
    fs::path dir = scratch("tiff");
    write(dir / "p.l", plant_l);
    write(dir / "p.v", plant_v);
    std::string files = (dir / "p.l").string() + " " + (dir / "p.v").string();
    ASSERT_EQ(run("-q -w 24 16 --spp 2 -o " + (dir / "o.tif").string() + " " + files).status, 0);
    auto opaque = OIIO::ImageInput::open((dir / "o.tif").string());
    ASSERT_TRUE(opaque);
    EXPECT_EQ(opaque->spec().nchannels, 3);

    ASSERT_EQ(run("-q --transparent -w 24 16 --spp 2 -o " + (dir / "t.tif").string() + " -o " +
                  (dir / "t.png").string() + " " + files)
                  .status,
              0);
    auto tif = OIIO::ImageInput::open((dir / "t.tif").string());
    auto png = OIIO::ImageInput::open((dir / "t.png").string());
    ASSERT_TRUE(tif && png);
    EXPECT_EQ(tif->spec().nchannels, 4);
    EXPECT_EQ(tif->spec().get_int_attribute("oiio:UnassociatedAlpha", 0), 0);
    std::vector<float> t(24 * 16 * 4), p(24 * 16 * 4);
    ASSERT_TRUE(tif->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, t.data()));
    // The PNG's straight colour, read without OIIO premultiplying it.
    OIIO::ImageSpec raw;
    raw.attribute("oiio:UnassociatedAlpha", 1);
    png = OIIO::ImageInput::open((dir / "t.png").string(), &raw);
    ASSERT_TRUE(png->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, p.data()));
    int background = 0, plant = 0;
    for (std::size_t i = 0; i < t.size(); i += 4) {
        EXPECT_NEAR(t[i + 3], p[i + 3], 1.0 / 255);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(t[i + c], p[i + c] * p[i + 3], 2.0 / 255) << i;
        background += t[i + 3] == 0 && t[i] == 0;
        plant += t[i + 3] == 1.0f;
    }
    EXPECT_GT(background, 0);
    EXPECT_GT(plant, 0);
}

// A symlink planted at the temporary name earlier versions used is never followed.
TEST(Command, PlantedSymlinkAtTemporaryNameIsNotFollowed)
{
    fs::path dir = scratch("symlink");
    write(dir / "p.l", plant_l);
    write(dir / "p.v", plant_v);
    write(dir / "victim", "precious");
    fs::create_symlink(dir / "victim", dir / "s.str.cambium-tmp");
    Result r = run("-q -str " + (dir / "s.str").string() + " " + (dir / "p.l").string() + " " +
                   (dir / "p.v").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(bytes_of(dir / "victim"), "precious");
    EXPECT_NE(bytes_of(dir / "s.str").find("F[+F]F"), std::string::npos);
}

TEST(Command, HugeGeometryIsRefusedWithAMessageNeverAnEmbreeAbort)
{
    // F(1e38) used to end in Embree's assertion `ray.valid()` (exit 134)
    fs::path dir = scratch("huge");
    write(dir / "h.l", "lsystem: 1\nderivation length: 1\naxiom: F(1e38)F(-1e38)@O(sqrt(-1))\nendlsystem\n");
    write(dir / "h.v", "line style: cylinder\n");
    Result r = run("-w 16 12 --spp 1 -o " + (dir / "out.png").string() + " " + (dir / "h.l").string() + " " +
                   (dir / "h.v").string());
    ASSERT_TRUE(WIFEXITED(r.status)) << r.output;
    EXPECT_EQ(WEXITSTATUS(r.status), 1) << r.output;
    EXPECT_NE(r.output.find("warning: 2 line segment(s) with coordinates or widths not finite or beyond 1e+10 "
                            "dropped"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("warning: 1 sphere(s) with a centre or diameter"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("error: the view volume reaches 1e+38"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
}

// Memory the system refuses within --max-memory (here an address-space limit on a
// film of 8192 x 8192) is a message that says so, never a bare "std::bad_alloc".
TEST(Command, MemoryTheSystemRefusesIsAMessageNotABareBadAlloc)
{
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer reserves its shadow memory past any address-space limit";
#else
    fs::path dir = scratch("refused");
    write(dir / "p.l", "lsystem: 1\nderivation length: 2\naxiom: A\nA --> F[+A][-A]\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\n");
    auto under_limit = [&](const std::string& size, const std::string& out) {
        return cambium::test::run_shell("ulimit -v 1500000 && exec " + std::string(CAMBIUM_EXE) + " --threads 2 -w " +
                                        size + " --spp 1 -o " + (dir / out).string() + " p.l p.v", dir);
    };
    Result small = under_limit("64 48", "small.png");  // the limit alone does not stop a run
    ASSERT_TRUE(WIFEXITED(small.status)) << small.output;
    ASSERT_EQ(WEXITSTATUS(small.status), 0) << small.output;
    Result r = under_limit("8192 8192", "big.png");
    ASSERT_TRUE(WIFEXITED(r.status)) << r.output;
    EXPECT_EQ(WEXITSTATUS(r.status), 1) << r.output;
    EXPECT_NE(r.output.find("error: out of memory: the system refused an allocation within the memory budget"),
              std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("std::bad_alloc"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "big.png"));
#endif
}

TEST(Command, NotANumberGeometryIsDroppedAndTheRestRenders)
{
    fs::path dir = scratch("nan");
    write(dir / "n.l", "lsystem: 1\nderivation length: 1\naxiom: F@O(sqrt(-1))F\nendlsystem\n");
    write(dir / "n.v", "line style: cylinder\n");
    Result r = run("-w 16 12 --spp 1 -o " + (dir / "out.png").string() + " " + (dir / "n.l").string() + " " +
                   (dir / "n.v").string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("warning: 1 sphere(s) with a centre or diameter not finite or beyond 1e+10 dropped"),
              std::string::npos)
        << r.output;
    EXPECT_TRUE(fs::exists(dir / "out.png"));
}

TEST(Command, ViewFileCameraOutOfRangeIsAnErrorAtItsColumn)
{
    fs::path dir = scratch("camera");
    write(dir / "p.l", "lsystem: 1\nderivation length: 1\naxiom: F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\nviewpoint: 0 0 1e30\n");
    Result r = run("-w 16 12 --spp 1 -o " + (dir / "out.png").string() + " " + (dir / "p.l").string() + " " +
                   (dir / "p.v").string());
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("p.v:2:16: error: value 1e+30 is out of range"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
}

// Warnings go to the command's diagnostics sink: printed once each, and not at all with -q.
TEST(Command, QuietMeansNoWarnings)
{
    fs::path dir = scratch("quiet");
    // ?E without -e: the L-system warns that no environment answers
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: F?E(1)\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\n");
    std::string args = "-w 16 12 --spp 1 -o " + (dir / "p.png").string() + " " +
                       (dir / "p.l").string() + " " + (dir / "p.v").string();
    Result loud = run(args);
    EXPECT_EQ(loud.status, 0) << loud.output;
    std::size_t first = loud.output.find("no environment is connected");
    EXPECT_NE(first, std::string::npos) << loud.output;
    EXPECT_EQ(loud.output.find("no environment is connected", first + 1), std::string::npos)
        << loud.output;
    Result quiet = run("-q " + args);
    EXPECT_EQ(quiet.status, 0) << quiet.output;
    EXPECT_EQ(quiet.output, "");
}

namespace {

/// A small growing plant: 3 steps, each adding a segment.
fs::path growing_plant(const fs::path& dir)
{
    write(dir / "g.l", "lsystem: 1\nderivation length: 3\naxiom: A\nA --> F[+F]A\nendlsystem\n");
    write(dir / "g.v", "line style: cylinder\ninitial line width: 0.2\n");
    return dir;
}

std::string plant_files(const fs::path& dir)
{
    return (dir / "g.l").string() + " " + (dir / "g.v").string();
}

}  // namespace

TEST(Sequence, AnimationWithoutAFileRendersEveryStepWithNumberedNames)
{
    fs::path dir = growing_plant(scratch("anim"));
    Result r = run("-a -q -w 24 18 --spp 1 -o " + (dir / "f%02d.png").string() + " -str " +
                   (dir / "s%d.str").string() + " " + plant_files(dir));
    ASSERT_EQ(r.status, 0) << r.output;
    // cpfg's defaults: 1 .. derivation length
    for (const char* file : {"f01.png", "f02.png", "f03.png", "s1.str", "s2.str", "s3.str"})
        EXPECT_TRUE(fs::exists(dir / file)) << file;
    EXPECT_FALSE(fs::exists(dir / "f00.png"));
    std::ifstream third(dir / "s3.str");
    std::string text((std::istreambuf_iterator<char>(third)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.substr(0, 10), "F[+F]F[+F]");
}

TEST(Sequence, AnimationFileSelectsFrames)
{
    fs::path dir = growing_plant(scratch("anim_file"));
    write(dir / "g.a", "first frame: 0\nlast frame: 3\nstep: 2\n");
    Result r = run("-a -q -str " + (dir / "s%d.str").string() + " " + plant_files(dir) + " " +
                   (dir / "g.a").string());
    ASSERT_EQ(r.status, 0) << r.output;
    // 0, 2, then 4: the last frame is reached or passed, past the derivation length
    EXPECT_TRUE(fs::exists(dir / "s0.str"));
    EXPECT_TRUE(fs::exists(dir / "s2.str"));
    EXPECT_TRUE(fs::exists(dir / "s4.str"));
    EXPECT_FALSE(fs::exists(dir / "s1.str"));
    EXPECT_FALSE(fs::exists(dir / "s3.str"));
}

// -ray writes cpfg's rayshade scene: a still's alone (nothing rendered), and one per frame
// through the name's number field, each with that frame's segments.
TEST(Command, RayshadeSceneOfAStillAndOfEveryFrame)
{
    fs::path dir = growing_plant(scratch("ray"));
    Result still = run("-q -ray " + (dir / "p.ray").string() + " " + plant_files(dir));
    ASSERT_EQ(still.status, 0) << still.output;
    std::string text = bytes_of(dir / "p.ray");
    EXPECT_NE(text.find("\nname p.ray\ngrid 40 40 40\n"), std::string::npos) << text;
    EXPECT_NE(text.find("\nobject p.ray\n"), std::string::npos) << text;
    EXPECT_FALSE(fs::exists(dir / "g.png"));  // only the scene was asked for

    Result frames = run("-a -q -ray " + (dir / "r%d.ray").string() + " " + plant_files(dir));
    ASSERT_EQ(frames.status, 0) << frames.output;
    auto cylinders = [](const std::string& t) {
        std::size_t n = 0;
        for (std::size_t at = t.find("\ncylinder "); at != std::string::npos; at = t.find("\ncylinder ", at + 1))
            ++n;
        return n;
    };
    ASSERT_TRUE(fs::exists(dir / "r1.ray") && fs::exists(dir / "r3.ray"));
    EXPECT_LT(cylinders(bytes_of(dir / "r1.ray")), cylinders(bytes_of(dir / "r3.ray")));
    EXPECT_EQ(cylinders(bytes_of(dir / "r3.ray")), cylinders(text));

    Result one = run("-a -q -ray " + (dir / "one.ray").string() + " " + plant_files(dir));
    EXPECT_NE(one.status, 0);
    EXPECT_NE(one.output.find("-ray names one file for"), std::string::npos) << one.output;
}

// -ps writes the window as PostScript: a still's alone (nothing rendered) with the page
// the window's size, and one per frame through the name's number field, each frame's
// drawing growing with its plant.
TEST(Command, PostScriptOfAStillAndOfEveryFrame)
{
    fs::path dir = growing_plant(scratch("ps"));
    Result still = run("-q -w 160 120 -ps " + (dir / "p.ps").string() + " " + plant_files(dir));
    ASSERT_EQ(still.status, 0) << still.output;
    std::string text = bytes_of(dir / "p.ps");
    EXPECT_EQ(text.rfind("%!PS", 0), 0u);
    EXPECT_NE(text.find("\n%%BoundingBox: 0 0 160 120\n"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir / "g.png"));  // only the drawing was asked for

    Result frames = run("-a -q -w 160 120 -ps " + (dir / "r%d.ps").string() + " " + plant_files(dir));
    ASSERT_EQ(frames.status, 0) << frames.output;
    ASSERT_TRUE(fs::exists(dir / "r1.ps") && fs::exists(dir / "r3.ps"));
    EXPECT_LT(fs::file_size(dir / "r1.ps"), fs::file_size(dir / "r3.ps"));

    Result one = run("-a -q -ps " + (dir / "one.ps").string() + " " + plant_files(dir));
    EXPECT_NE(one.status, 0);
    EXPECT_NE(one.output.find("-ps names one file for"), std::string::npos) << one.output;
    // -o drawings are written per frame too; a turntable, one geometry, refuses them
    Result svg = run("-a -q -o " + (dir / "f%d.svg").string() + " " + plant_files(dir));
    ASSERT_EQ(svg.status, 0) << svg.output;
    EXPECT_LT(fs::file_size(dir / "f1.svg"), fs::file_size(dir / "f3.svg"));
    Result turn = run("--turntable 3 -q -o " + (dir / "t%d.pdf").string() + " " + plant_files(dir));
    EXPECT_NE(turn.status, 0);
    EXPECT_NE(turn.output.find("a turntable turns one geometry"), std::string::npos) << turn.output;
    EXPECT_FALSE(fs::exists(dir / "t1.pdf"));
    for (const char* option : {"-ray", "-ps", "-iv"}) {  // not silently dropped either
        Result r = run(std::string("--turntable 3 -q ") + option + " " + (dir / "t.x").string() +
                       " -o " + (dir / "t%d.png").string() + " " + plant_files(dir));
        EXPECT_NE(r.status, 0) << option;
        EXPECT_NE(r.output.find("write " + std::string(option) + " from a still"), std::string::npos)
            << r.output;
        EXPECT_FALSE(fs::exists(dir / "t.x") || fs::exists(dir / "t1.png")) << option;
    }
}

/// A mesh file's lines but its `mtllib` one (which names the file's own MTL).
std::string without_mtllib(const std::string& obj)
{
    std::istringstream in(obj);
    std::string out, line;
    while (std::getline(in, line))
        if (line.rfind("mtllib ", 0) != 0)
            out += line + "\n";
    return out;
}

// An -a animation writes an OBJ per frame, each the geometry of a still derived to that
// frame's step; the name needs a number field.
TEST(Command, MeshOfEveryFrameIsTheStillOfItsStep)
{
    fs::path dir = growing_plant(scratch("objframes"));
    Result frames = run("-a -q -o " + (dir / "m%d.obj").string() + " " + plant_files(dir));
    ASSERT_EQ(frames.status, 0) << frames.output;
    for (int step = 1; step <= 3; ++step) {
        const std::string still = "s" + std::to_string(step) + ".obj";
        Result r = run("-q --steps " + std::to_string(step) + " -o " + (dir / still).string() +
                       " " + plant_files(dir));
        ASSERT_EQ(r.status, 0) << r.output;
        const std::string framed = bytes_of(dir / ("m" + std::to_string(step) + ".obj"));
        EXPECT_NE(framed.find("\nv "), std::string::npos);
        EXPECT_EQ(without_mtllib(framed), without_mtllib(bytes_of(dir / still))) << "step " << step;
    }
    EXPECT_LT(fs::file_size(dir / "m1.obj"), fs::file_size(dir / "m3.obj"));
    Result one = run("-a -q -o " + (dir / "one.obj").string() + " " + plant_files(dir));
    EXPECT_NE(one.status, 0);
    EXPECT_NE(one.output.find("-o names one file for"), std::string::npos) << one.output;
    EXPECT_FALSE(fs::exists(dir / "one.obj"));
}

// -iv writes the plant as an Inventor 2.1 scene: a still's alone, and one per frame.
TEST(Command, InventorOfAStillAndOfEveryFrame)
{
    fs::path dir = growing_plant(scratch("iv"));
    Result still = run("-q -iv " + (dir / "p.iv").string() + " " + plant_files(dir));
    ASSERT_EQ(still.status, 0) << still.output;
    const std::string text = bytes_of(dir / "p.iv");
    EXPECT_EQ(text.rfind("#Inventor V2.1 ascii\n", 0), 0u);
    EXPECT_NE(text.find("IndexedFaceSet"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir / "g.png"));
    Result frames = run("-a -q -iv " + (dir / "r%d.iv").string() + " " + plant_files(dir));
    ASSERT_EQ(frames.status, 0) << frames.output;
    ASSERT_TRUE(fs::exists(dir / "r1.iv") && fs::exists(dir / "r3.iv"));
    EXPECT_LT(fs::file_size(dir / "r1.iv"), fs::file_size(dir / "r3.iv"));
}

// -o chooses SVG and PDF by the extension; a picture beside them is still rendered.
TEST(Command, SvgAndPdfByTheOutputsExtension)
{
    fs::path dir = growing_plant(scratch("svg"));
    Result r = run("-q -w 64 48 --spp 1 -o " + (dir / "p.svg").string() + " -o " +
                   (dir / "p.pdf").string() + " -o " + (dir / "p.png").string() + " " +
                   plant_files(dir));
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string svg = bytes_of(dir / "p.svg");
    EXPECT_NE(svg.find("viewBox=\"0 0 64 48\""), std::string::npos) << svg.substr(0, 400);
    EXPECT_NE(svg.find("<path"), std::string::npos);
    EXPECT_EQ(bytes_of(dir / "p.pdf").rfind("%PDF-", 0), 0u);
    EXPECT_TRUE(fs::exists(dir / "p.png"));
}

// A -ps name in a folder that does not exist, or one past --max-memory, fails with a
// message naming it, as -ray's does, and leaves no file (partial or temporary) behind.
TEST(Command, PostScriptThatCannotBeWrittenLeavesNothing)
{
    fs::path dir = growing_plant(scratch("ps_bad"));
    Result ray = run("-q -ray " + (dir / "no" / "p.ray").string() + " " + plant_files(dir));
    Result ps = run("-q -ps " + (dir / "no" / "p.ps").string() + " " + plant_files(dir));
    EXPECT_NE(ray.status, 0);
    EXPECT_NE(ps.status, 0);
    EXPECT_NE(ps.output.find((dir / "no" / "p.ps").string()), std::string::npos) << ps.output;
    EXPECT_FALSE(fs::exists(dir / "no"));
    // enough for the derivation and the scene, not for the drawing's 144 shapes
    Result big = run("-q --max-memory 20K -ps " + (dir / "p.ps").string() + " " + plant_files(dir));
    EXPECT_NE(big.status, 0);
    EXPECT_NE(big.output.find("p.ps: the drawing's 144 shapes need"), std::string::npos) << big.output;
    EXPECT_NE(big.output.find("memory budget"), std::string::npos) << big.output;
    std::size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir))
        files += e.path().filename() != "g.l" && e.path().filename() != "g.v";
    EXPECT_EQ(files, 0u);
}

// --organ-masks in an animation: an organ keeps its name from frame to frame (its index
// where it appeared @ that frame's step), though new modules shift string indices.
TEST(Sequence, OrganMaskNamesAreStableAcrossFrames)
{
    fs::path dir = growing_plant(scratch("anim_masks"));
    Result r = run("-a -q -w 48 36 --spp 2 --organ-masks -o " + (dir / "f%02d.exr").string() + " " +
                   plant_files(dir));
    ASSERT_EQ(r.status, 0) << r.output;
    auto manifest = [&](const char* file) {
        auto in = OIIO::ImageInput::open((dir / file).string());
        EXPECT_TRUE(in) << file;
        if (!in)
            return std::string();
        std::string m = in->spec().get_string_attribute("cryptomatte/e72bb61/manifest");
        in->close();
        return m;
    };
    // F[+F]A, then F[+F]F[+F]A: the first frame's F modules keep their names
    const std::string first = manifest("f01.exr"), second = manifest("f02.exr"), third = manifest("f03.exr");
    for (const std::string& m : {first, second, third}) {
        EXPECT_NE(m.find("\"F 0@1\""), std::string::npos) << m;
        EXPECT_NE(m.find("\"F 3@1\""), std::string::npos) << m;
    }
    for (const std::string& m : {second, third}) {
        EXPECT_NE(m.find("\"F 5@2\""), std::string::npos) << m;
        EXPECT_NE(m.find("\"F 8@2\""), std::string::npos) << m;
    }
    EXPECT_NE(third.find("\"F 10@3\""), std::string::npos) << third;
    EXPECT_EQ(first.find("@2"), std::string::npos) << first;

    // through a homomorphism the organs keep the derived string's symbols (I, not F)
    write(dir / "h.l", "lsystem: 1\nderivation length: 2\naxiom: A\nA --> I[+I]A\n"
                       "homomorphism\nI --> F\nendlsystem\n");
    r = run("-a -q -w 48 36 --spp 2 --organ-masks -o " + (dir / "h%02d.exr").string() + " " +
            (dir / "h.l").string() + " " + (dir / "g.v").string());
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string h2 = manifest("h02.exr");
    EXPECT_NE(h2.find("\"I 0@1\""), std::string::npos) << h2;
    EXPECT_EQ(h2.find("\"F "), std::string::npos) << h2;
}

// In-between frames (--inbetween) hold the next frame's modules growing: they carry
// those modules' names, so one picked id follows an organ through them too.
TEST(Sequence, OrganMaskNamesAreStableThroughInBetweenFrames)
{
    fs::path dir = growing_plant(scratch("anim_masks_between"));
    Result r = run("-a -q -w 48 36 --spp 2 --inbetween 1 --organ-masks -o " + (dir / "f%02d.exr").string() +
                   " " + plant_files(dir));
    ASSERT_EQ(r.status, 0) << r.output;
    auto in = OIIO::ImageInput::open((dir / "f02.exr").string());  // between the first two frames
    ASSERT_TRUE(in);
    const std::string m = in->spec().get_string_attribute("cryptomatte/e72bb61/manifest");
    in->close();
    EXPECT_NE(m.find("\"F 0@1\""), std::string::npos) << m;
    EXPECT_NE(m.find("\"F 5@2\""), std::string::npos) << m;  // growing from nothing, already named
    EXPECT_EQ(m.find("\"F 5\""), std::string::npos) << m;    // no bare string index
}

TEST(Sequence, SeveralFramesIntoOneNameIsAnErrorBeforeAnyWork)
{
    fs::path dir = growing_plant(scratch("anim_name"));
    Result r = run("-a -q -o " + (dir / "one.png").string() + " " + plant_files(dir));
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("number field"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "one.png"));
}

TEST(Sequence, TurntableFramesSubsetAndResume)
{
    fs::path dir = growing_plant(scratch("turn"));
    std::string common = "-q -w 24 18 --spp 1 --turntable 6 -o " + (dir / "t%d.png").string() +
                         " " + plant_files(dir);
    Result r = run("--frames 2-3 " + common);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_FALSE(fs::exists(dir / "t1.png"));
    EXPECT_TRUE(fs::exists(dir / "t2.png"));
    EXPECT_TRUE(fs::exists(dir / "t3.png"));
    EXPECT_FALSE(fs::exists(dir / "t4.png"));
    // --resume leaves frames already written alone and renders the rest
    auto written = fs::last_write_time(dir / "t2.png");
    r = run("--resume " + common);
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* frame : {"t1.png", "t2.png", "t3.png", "t4.png", "t5.png", "t6.png"})
        EXPECT_TRUE(fs::exists(dir / frame)) << frame;
    EXPECT_EQ(fs::last_write_time(dir / "t2.png"), written);
}

TEST(Sequence, VideoWithoutFfmpegSaysHowToInstallIt)
{
    fs::path dir = growing_plant(scratch("video"));
    std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
    setenv("PATH", dir.c_str(), 1);  // no ffmpeg there
    Result r = run("-q --turntable 4 -o " + (dir / "t.mp4").string() + " " + plant_files(dir));
    setenv("PATH", path.c_str(), 1);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("apt-get install ffmpeg"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "t.mp4"));
    EXPECT_FALSE(fs::exists(dir / "t.mp4.frames"));
}

TEST(Sequence, TurntableVideoWithFfmpeg)
{
    if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "ffmpeg is not installed";
    fs::path dir = growing_plant(scratch("video_ok"));
    Result r = run("-q -w 24 18 --spp 1 --turntable 4 -o " + (dir / "t.mp4").string() + " " +
                   plant_files(dir));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_GT(fs::file_size(dir / "t.mp4"), 0u);
    EXPECT_FALSE(fs::exists(dir / "t.mp4.frames"));  // the frames go once encoded
}

// A model folder that plants links and frames at the names videos once used reaches
// nothing: a stand-in ffmpeg (the real one is not needed to check this) writes the list
// of frames it was given as the "video".
TEST(Sequence, VideoWorksInAPrivateFolder)
{
    fs::path dir = growing_plant(scratch("video_planted"));
    fs::path outside = dir / "outside";
    fs::create_directories(outside / "frames");
    write(outside / "victim", "precious");
    fs::create_symlink(outside / "victim", dir / "t.mp4.cambium-tmp.mp4");
    fs::create_directory_symlink(outside / "frames", dir / "t.mp4.frames");
    fs::create_directories(dir / "u.mp4.frames");
    write(dir / "u.mp4.frames" / "000000.png", "planted");
    ::mkfifo((dir / "u.mp4.cambium-tmp.mp4").c_str(), 0600);
    fs::path bin = dir / "bin";
    fs::create_directories(bin);
    write(bin / "ffmpeg", "#!/bin/sh\nfor last; do :; done\nls *.png > \"$last\"\n");
    fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
    std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
    setenv("PATH", (bin.string() + ":" + path).c_str(), 1);
    Result r = run("-q -w 8 6 --spp 1 --turntable 3 -o " + (dir / "t.mp4").string() + " -o " +
                   (dir / "u.mp4").string() + " " + plant_files(dir));
    setenv("PATH", path.c_str(), 1);
    ASSERT_EQ(r.status, 0) << r.output;
    std::string frames = "000001.png\n000002.png\n000003.png\n";
    std::ifstream t(dir / "t.mp4"), u(dir / "u.mp4");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(t), {}), frames);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(u), {}), frames);  // not 000000
    std::ifstream victim(outside / "victim");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(victim), {}), "precious");
    EXPECT_TRUE(fs::is_empty(outside / "frames"));
    for (const auto& entry : fs::directory_iterator(dir))  // no work folder left
        EXPECT_EQ(entry.path().filename().string().find(".t.cambium-"), std::string::npos);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 10);
}

TEST(Staging, GroundUnderThePlantAndShadowCatcher)
{
    fs::path dir = growing_plant(scratch("ground"));
    write(dir / "g.v", "line style: cylinder\ninitial line width: 0.2\nlight: V: 0.3 1 0.2\n");
    std::string common = "-q -w 32 24 --spp 4 --orbit 0 30 " + plant_files(dir);
    // Without a ground the bottom corners are background; with one, ground (grey).
    Result r = run("--transparent -o " + (dir / "bare.exr").string() + " " + common);
    ASSERT_EQ(r.status, 0) << r.output;
    r = run("--ground -o " + (dir / "ground.exr").string() + " " + common);
    ASSERT_EQ(r.status, 0) << r.output;
    r = run("--ground '#ff0000' -o " + (dir / "red.exr").string() + " " + common);
    ASSERT_EQ(r.status, 0) << r.output;
    r = run("--shadow-catcher -o " + (dir / "catcher.exr").string() + " " + common);
    ASSERT_EQ(r.status, 0) << r.output;
    Picture bare = read_picture(dir / "bare.exr"), ground = read_picture(dir / "ground.exr");
    Picture red = read_picture(dir / "red.exr"), catcher = read_picture(dir / "catcher.exr");
    ASSERT_EQ(ground.width, 32);
    int a = ground.channel("A");
    ASSERT_GE(a, 0);
    EXPECT_EQ(bare.at(1, 22, a), 0.0f);
    EXPECT_EQ(ground.at(1, 22, a), 1.0f);
    EXPECT_GT(ground.at(1, 22, 0), 0.0f);
    EXPECT_NEAR(ground.at(1, 22, 0), ground.at(1, 22, 2), 1e-6);  // grey
    EXPECT_GT(red.at(1, 22, 0), 10 * red.at(1, 22, 2));           // red
    // The catcher: transparent where nothing shadows it, the plant still opaque.
    EXPECT_EQ(catcher.at(1, 22, a), 0.0f);
    float plant_alpha = 0;
    for (int x = 0; x < 32; ++x)
        plant_alpha = std::max(plant_alpha, catcher.at(x, 12, a));
    EXPECT_EQ(plant_alpha, 1.0f);
}

TEST(Staging, GroundAndInbetweenOptionsAreChecked)
{
    fs::path dir = growing_plant(scratch("ground_bad"));
    Result r = run("-q --ground 2,0,0 -o " + (dir / "x.png").string() + " " + plant_files(dir));
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("--ground"), std::string::npos) << r.output;
    r = run("-q --ground " + (dir / "missing.png").string() + " -o " + (dir / "x.png").string() +
            " " + plant_files(dir));
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("missing.png"), std::string::npos) << r.output;
    r = run("-q --inbetween 2 -o " + (dir / "x.png").string() + " " + plant_files(dir));
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("-a"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(Sequence, InbetweenFramesAreNumberedBetweenTheSteps)
{
    fs::path dir = growing_plant(scratch("inbetween"));
    Result r = run("-a -q -w 24 18 --spp 1 --inbetween 2 -o " + (dir / "f%02d.png").string() +
                   " -str " + (dir / "s%d.str").string() + " " + plant_files(dir));
    ASSERT_EQ(r.status, 0) << r.output;
    // steps 1, 2, 3 are frames 1, 4, 7; two in-betweens lead to each of the last two
    for (int n = 1; n <= 7; ++n)
        EXPECT_TRUE(fs::exists(dir / fmt_number("f%02d.png", n))) << n;
    EXPECT_FALSE(fs::exists(dir / "f08.png"));
    // strings keep the derivation steps' numbers
    for (const char* file : {"s1.str", "s2.str", "s3.str"})
        EXPECT_TRUE(fs::exists(dir / file)) << file;
    EXPECT_FALSE(fs::exists(dir / "s4.str"));
    // an in-between differs from both steps around it
    Picture step1 = read_picture(dir / "f01.png"), between = read_picture(dir / "f02.png");
    Picture step2 = read_picture(dir / "f04.png");
    EXPECT_GT(rgb_difference(step1, between), 0);
    EXPECT_GT(rgb_difference(between, step2), 0);
}
