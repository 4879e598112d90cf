// SPDX-License-Identifier: Apache-2.0
// Rendering in pieces (docs/distributed.md): bands and tile files (app/tiles.h), and the
// cambium command with --tile/--assemble and under mpirun with --mpi, whose files must
// equal a single process's byte for byte.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "app/tiles.h"
#include "shell_output.h"
#include "base/diagnostics.h"

namespace fs = std::filesystem;

namespace cambium::app {
namespace {

using Result = cambium::test::CommandResult;

/// Runs `command` in scenes/default (the model the runs render).
Result shell(const std::string& command)
{
    return cambium::test::run_shell(command, CAMBIUM_SOURCE_DIR "/scenes/default");
}

const std::string cambium = CAMBIUM_EXE;

fs::path scratch(const std::string& name)
{
    fs::path dir = fs::temp_directory_path() /
                   ("cambium_dist_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string bytes_of(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Both files exist and hold the same bytes.
void expect_same_file(const fs::path& a, const fs::path& b)
{
    ASSERT_TRUE(fs::exists(a)) << a;
    ASSERT_TRUE(fs::exists(b)) << b;
    EXPECT_GT(fs::file_size(a), 0u);
    EXPECT_TRUE(bytes_of(a) == bytes_of(b)) << a << " and " << b << " differ";
}

/// The mpirun to use, or a reason to skip.
std::string mpirun_or_skip_reason()
{
    if (std::system("command -v mpirun >/dev/null 2>&1") != 0)
        return "mpirun is not installed (apt-get install openmpi-bin libopenmpi-dev)";
    if (!CAMBIUM_HAVE_MPI_MODULE)
        return "this build has no libcambium_mpi.so (MPI was not found at configure time)";
    // Open MPI refuses root unless told; oversubscribe: more ranks than cores.
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    // Under `make sanitize`: Open MPI keeps its allocations until exit, some in components
    // it has unloaded before LeakSanitizer looks (no module name to suppress), so the
    // ranks are checked for memory errors but not for leaks.
    if (const char* asan = std::getenv("ASAN_OPTIONS"))
        setenv("ASAN_OPTIONS", (std::string(asan) + ":detect_leaks=0").c_str(), 1);
    return {};
}

std::string mpirun(int ranks)
{
    return "mpirun --oversubscribe -np " + std::to_string(ranks) + " " + cambium + " --mpi";
}

// A still with adaptive sampling (whose decisions cross band edges) and every EXR layer.
const std::string still = "-q -w 40 30 --spp 32 --noise-target 0.05 --seed 3 plant.l plant.v";

TEST(Bands, CoverEveryRowOnce)
{
    for (int count : {1, 2, 3, 7, 30}) {
        int next = 0;
        for (int i = 0; i < count; ++i) {
            render::PixelRect r = band(i, count, 40, 30);
            EXPECT_EQ(r.x, 0);
            EXPECT_EQ(r.width, 40);
            EXPECT_EQ(r.y, next);
            EXPECT_GE(r.height, 30 / count);
            next = r.y + r.height;
        }
        EXPECT_EQ(next, 30);
    }
}

TEST(Tiles, EncodeDecodeAndPasteKeepEveryBit)
{
    render::Image part = blank_image(3, 2, true, true);
    for (std::size_t i = 0; i < part.rgba.size(); ++i)
        part.rgba[i] = 0.1f * float(i) + 1e-7f;
    part.depth[4] = 2.5f;
    part.normal[5] = -0.25f;
    Tile tile{1, 4, 5, 8, {2, 3, 3, 2}, part};
    Tile back = decode_tile(encode_tile(tile), "test");
    EXPECT_EQ(back.rect, tile.rect);
    EXPECT_EQ(back.index, 1);
    EXPECT_EQ(back.count, 4);
    EXPECT_TRUE(back.image.transparent);
    EXPECT_EQ(back.image.rgba, part.rgba);
    EXPECT_EQ(back.image.depth, part.depth);
    EXPECT_EQ(back.image.normal, part.normal);
    render::Image whole = blank_image(5, 8, true, true);
    paste(whole, back.image, 2, 3);
    EXPECT_EQ(whole.at(2, 3, 0), part.at(0, 0, 0));
    EXPECT_EQ(whole.at(4, 4, 3), part.at(2, 1, 3));
    EXPECT_EQ(whole.depth[std::size_t(4) * 5 + 3], 2.5f);
    EXPECT_EQ(whole.at(1, 3, 0), 0.0f);  // left of the tile: untouched
    EXPECT_THROW(paste(whole, back.image, 3, 3), Error);
}

TEST(Tiles, DamagedFilesAreRefused)
{
    Tile tile{0, 1, 2, 2, {0, 0, 2, 2}, blank_image(2, 2, false, false)};
    std::string bytes = encode_tile(tile);
    EXPECT_THROW(decode_tile("not a tile", "f"), Error);
    EXPECT_THROW(decode_tile(bytes.substr(0, bytes.size() - 1), "f"), Error);
    std::string wrong = bytes;
    wrong[std::string("cambium tile 1\n").size() + 4 * 4] = 9;  // x beyond the image
    EXPECT_THROW(decode_tile(wrong, "f"), Error);
}

/// The message of assembling `count` tiles of a width x height image named `output`.
std::string assembly_error(const fs::path& output, int count, int width, int height)
{
    try {
        assemble_tiles(output, count, width, height);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

// A tile is a regular file no larger than its band could need, both checked before it
// is read: a FIFO would block forever, a huge file would be held whole.
TEST(Tiles, AssemblyReadsOnlyRegularFilesOfTheirBandsSize)
{
    fs::path dir = scratch("tile_files");
    fs::path out = dir / "t.png";
    ASSERT_EQ(::mkfifo(tile_file(out, 0, 2).c_str(), 0600), 0);
    EXPECT_NE(assembly_error(out, 2, 4, 4).find("t.tile0of2.ctile: error: cannot open the tile: not a regular file"),
              std::string::npos)
        << assembly_error(out, 2, 4, 4);
    fs::remove(tile_file(out, 0, 2));
    // the band is 4x2 pixels: 15 + 40 + 8 * 11 * 4 = 407 bytes at most
    std::ofstream(tile_file(out, 0, 2)) << std::string(408, 'x');
    EXPECT_NE(assembly_error(out, 2, 4, 4).find("the tile is too large (408 bytes; the limit is 407)"),
              std::string::npos)
        << assembly_error(out, 2, 4, 4);
    fs::remove_all(dir);
}

TEST(TileCommand, AssembledTilesEqualTheSingleRun)
{
    fs::path dir = scratch("tile");
    std::string single = " -o " + (dir / "one.png").string() + " -o " + (dir / "one.exr").string();
    std::string tiled = " -o " + (dir / "t.png").string() + " -o " + (dir / "t.exr").string();
    ASSERT_EQ(shell(cambium + " " + still + single).status, 0);
    for (int i = 0; i < 3; ++i) {
        Result r = shell(cambium + " --tile " + std::to_string(i) + "/3 " + still + tiled);
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_TRUE(fs::exists(dir / ("t.tile" + std::to_string(i) + "of3.ctile")));
    }
    EXPECT_FALSE(fs::exists(dir / "t.png"));  // tiles only
    Result r = shell(cambium + " --assemble 3 " + still + tiled);
    ASSERT_EQ(r.status, 0) << r.output;
    expect_same_file(dir / "one.png", dir / "t.png");
    expect_same_file(dir / "one.exr", dir / "t.exr");

    // A missing tile, or tiles of another split, stop the assembly with the file's name.
    fs::remove(dir / "t.png");
    r = shell(cambium + " --assemble 4 " + still + tiled);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("t.tile0of4.ctile"), std::string::npos) << r.output;
    fs::rename(dir / "t.tile2of3.ctile", dir / "t.tile1of3.ctile");
    r = shell(cambium + " --assemble 3 " + still + tiled);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("is tile 2 of 3"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "t.png"));
    fs::remove_all(dir);
}

TEST(MpiCommand, StillEqualsTheSingleRun)
{
    std::string skip = mpirun_or_skip_reason();
    if (!skip.empty())
        GTEST_SKIP() << skip;
    fs::path dir = scratch("mpi_still");
    auto outputs = [&](const std::string& name) {
        return " -o " + (dir / (name + ".png")).string() + " -o " + (dir / (name + ".exr")).string();
    };
    ASSERT_EQ(shell(cambium + " " + still + outputs("one")).status, 0);
    for (int ranks : {2, 3}) {
        std::string name = "np" + std::to_string(ranks);
        Result r = shell(mpirun(ranks) + " --threads 1 " + still + outputs(name));
        ASSERT_EQ(r.status, 0) << r.output;
        expect_same_file(dir / "one.png", dir / (name + ".png"));
        expect_same_file(dir / "one.exr", dir / (name + ".exr"));
    }
    fs::remove_all(dir);
}

TEST(MpiCommand, SequencesEqualTheSingleRun)
{
    std::string skip = mpirun_or_skip_reason();
    if (!skip.empty())
        GTEST_SKIP() << skip;
    fs::path dir = scratch("mpi_sequence");
    // A turntable of 4 frames on 3 ranks (rank 0 renders two), a growth animation of 3
    // frames on 2.
    const std::string turntable = "-q -w 24 18 --spp 4 --turntable 4 plant.l plant.v";
    const std::string growth = "-q -w 24 18 --spp 4 -a --steps 3 plant.l plant.v";
    auto outputs = [&](const std::string& name) {
        return " -o " + (dir / (name + "%02d.png")).string() + " -o " +
               (dir / (name + "%02d.exr")).string();
    };
    ASSERT_EQ(shell(cambium + " " + turntable + outputs("turn")).status, 0);
    ASSERT_EQ(shell(cambium + " " + growth + outputs("grow")).status, 0);
    Result r = shell(mpirun(3) + " --threads 1 " + turntable + outputs("turn_np3_"));
    ASSERT_EQ(r.status, 0) << r.output;
    r = shell(mpirun(2) + " --threads 1 " + growth + outputs("grow_np2_"));
    ASSERT_EQ(r.status, 0) << r.output;
    for (int frame = 1; frame <= 4; ++frame)
        for (const char* ext : {".png", ".exr"}) {
            char number[8];
            std::snprintf(number, sizeof number, "%02d", frame);
            expect_same_file(dir / ("turn" + std::string(number) + ext),
                             dir / ("turn_np3_" + std::string(number) + ext));
            if (frame <= 3)
                expect_same_file(dir / ("grow" + std::string(number) + ext),
                                 dir / ("grow_np2_" + std::string(number) + ext));
        }
    EXPECT_FALSE(fs::exists(dir / "grow04.png"));
    fs::remove_all(dir);
}

/// "%02d" of n.
std::string two_digits(int n)
{
    char number[16];  // room for any int
    std::snprintf(number, sizeof number, "%02d", n);
    return number;
}

TEST(MpiCommand, FramesOnDemandEqualTheSingleRun)
{
    // Animations hand frames out on demand (app/distributed.h, FrameQueue): more frames
    // than ranks, in-betweens, and more ranks than frames must all give the single run's
    // files, each frame written once.
    std::string skip = mpirun_or_skip_reason();
    if (!skip.empty())
        GTEST_SKIP() << skip;
    fs::path dir = scratch("mpi_queue");
    struct Case {
        std::string name, args;
        int ranks, frames;
    };
    const std::vector<Case> cases = {
        {"between", "-q -w 16 12 --spp 2 -a --steps 3 --inbetween 1 plant.l plant.v", 3, 5},
        {"few", "-q -w 16 12 --spp 2 -a --steps 2 plant.l plant.v", 3, 2},
    };
    for (const Case& c : cases) {
        std::string one = " -o " + (dir / (c.name + "%02d.png")).string();
        std::string many = " -o " + (dir / (c.name + "_mpi%02d.png")).string();
        ASSERT_EQ(shell(cambium + " " + c.args + one).status, 0) << c.name;
        Result r = shell(mpirun(c.ranks) + " --threads 1 " + c.args + many);
        ASSERT_EQ(r.status, 0) << c.name << "\n" << r.output;
        for (int frame = 1; frame <= c.frames; ++frame)
            expect_same_file(dir / (c.name + two_digits(frame) + ".png"),
                             dir / (c.name + "_mpi" + two_digits(frame) + ".png"));
        EXPECT_FALSE(fs::exists(dir / (c.name + "_mpi" + two_digits(c.frames + 1) + ".png")));
    }
    fs::remove_all(dir);
}

TEST(MpiCommand, ResumeSkipsTheFramesRank0FindsWritten)
{
    std::string skip = mpirun_or_skip_reason();
    if (!skip.empty())
        GTEST_SKIP() << skip;
    fs::path dir = scratch("mpi_resume");
    const std::string growth = "-w 16 12 --spp 2 -a --steps 4 plant.l plant.v";
    const std::string turntable = "-w 16 12 --spp 2 --turntable 4 plant.l plant.v";
    for (const auto& [name, args, ranks] :
         {std::tuple{std::string("grow"), growth, 2}, std::tuple{std::string("turn"), turntable, 3}}) {
        ASSERT_EQ(shell(cambium + " -q " + args + " -o " + (dir / (name + "%02d.png")).string())
                      .status,
                  0);
        // Frames 2 and 3 are "written already": their stand-ins must stay untouched.
        for (int frame : {2, 3})
            std::ofstream(dir / (name + "_mpi" + two_digits(frame) + ".png")) << "kept";
        Result r = shell(mpirun(ranks) + " --threads 1 --resume " + args + " -o " +
                         (dir / (name + "_mpi%02d.png")).string());
        ASSERT_EQ(r.status, 0) << name << "\n" << r.output;
        EXPECT_NE(r.output.find("4 frames, 2 to render"), std::string::npos) << r.output;
        for (int frame : {1, 4})
            expect_same_file(dir / (name + two_digits(frame) + ".png"),
                             dir / (name + "_mpi" + two_digits(frame) + ".png"));
        for (int frame : {2, 3})
            EXPECT_EQ(bytes_of(dir / (name + "_mpi" + two_digits(frame) + ".png")), "kept");
    }
    fs::remove_all(dir);
}

TEST(MpiCommand, AnErrorEndsEveryRankAndIsPrintedOnce)
{
    std::string skip = mpirun_or_skip_reason();
    if (!skip.empty())
        GTEST_SKIP() << skip;
    fs::path dir = scratch("mpi_error");
    std::ofstream(dir / "bad.l") << "lsystem: 1\nderivation length: 1\nAxiom: F(\nendlsystem\n";
    Result r = shell(mpirun(3) + " -w 24 18 -o " + (dir / "x.png").string() + " " +
                     (dir / "bad.l").string() + " plant.v");
    EXPECT_NE(r.status, 0);
    std::size_t first = r.output.find("bad.l:3");
    ASSERT_NE(first, std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("bad.l:3", first + 1), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.png"));
    fs::remove_all(dir);
}

}  // namespace
}  // namespace cambium::app
