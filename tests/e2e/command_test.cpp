// SPDX-License-Identifier: Apache-2.0
// The cambium command as a user runs it: exit status, messages, output files.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>

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
    fs::path dir = fs::temp_directory_path() / ("cambium_cmd_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

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
    EXPECT_GT(fs::file_size(dir / "p.png"), 0u);
    EXPECT_GT(fs::file_size(dir / "p.exr"), 0u);
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
