// SPDX-License-Identifier: Apache-2.0
// The cambium command as a user runs it: exit status, messages, output files.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Result {
    int status;
    std::string output;  // stdout and stderr
};

Result run(const std::string& args)
{
    std::string command = std::string(CAMBIUM_EXE) + " " + args + " 2>&1";
    Result r{0, {}};
    FILE* pipe = popen(command.c_str(), "r");
    std::array<char, 512> buffer{};
    while (fgets(buffer.data(), buffer.size(), pipe))
        r.output += buffer.data();
    r.status = pclose(pipe);
    return r;
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
}

// Warnings go to the command's diagnostics sink: printed once each, and not at all with -q.
TEST(Command, QuietMeansNoWarnings)
{
    fs::path dir = scratch("quiet");
    write(dir / "p.l", "lsystem: 1\nderivation length: 0\naxiom: F\nendlsystem\n");
    write(dir / "p.v", "line style: cylinder\n");
    write(dir / "p.e", "\n");
    std::string args = "-w 16 12 --spp 1 -e " + (dir / "p.e").string() + " -o " +
                       (dir / "p.png").string() + " " + (dir / "p.l").string() + " " +
                       (dir / "p.v").string();
    Result loud = run(args);
    EXPECT_EQ(loud.status, 0) << loud.output;
    std::size_t first = loud.output.find("warning: -e:");
    EXPECT_NE(first, std::string::npos) << loud.output;
    EXPECT_EQ(loud.output.find("warning: -e:", first + 1), std::string::npos) << loud.output;
    Result quiet = run("-q " + args);
    EXPECT_EQ(quiet.status, 0) << quiet.output;
    EXPECT_EQ(quiet.output, "");
}
