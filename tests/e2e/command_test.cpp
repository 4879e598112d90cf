// SPDX-License-Identifier: Apache-2.0
// The cambium command as a user runs it: exit status, messages, output files.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

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
