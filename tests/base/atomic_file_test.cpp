// SPDX-License-Identifier: Apache-2.0
// Atomic output files: whole or absent, never through a planted link.
#include "base/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "base/diagnostics.h"
#include "scratch.h"

namespace cambium {
namespace {

namespace fs = std::filesystem;

using testing::scratch;

std::string contents(const fs::path& file)
{
    std::ifstream in(file);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

void write_text(const fs::path& file, const std::string& text)
{
    write_file_atomically(file, [&](const fs::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << text;
        if (!out)
            throw Error("write failed");
    });
}

TEST(AtomicFile, WritesAndReplaces)
{
    fs::path dir = scratch("replace");
    write_text(dir / "a.txt", "one");
    write_text(dir / "a.txt", "two");
    EXPECT_EQ(contents(dir / "a.txt"), "two");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
    auto perms = fs::status(dir / "a.txt").permissions();
    EXPECT_NE(perms & fs::perms::owner_read, fs::perms::none);
}

// Symlinks planted at the names earlier versions used (`<file>.cambium-tmp`, and
// every name a predictable scheme could give) are never written through.
TEST(AtomicFile, PlantedSymlinksAreNotFollowed)
{
    fs::path dir = scratch("symlink");
    std::ofstream(dir / "victim") << "precious";
    fs::create_symlink(dir / "victim", dir / "out.str.cambium-tmp");
    fs::create_symlink(dir / "victim", dir / ".out.cambium-XXXXXX.str");
    write_text(dir / "out.str", "new");
    EXPECT_EQ(contents(dir / "victim"), "precious");
    EXPECT_EQ(contents(dir / "out.str"), "new");
    EXPECT_FALSE(fs::is_symlink(dir / "out.str"));
}

// The writer gets a path that reaches the temporary file it was given, even if the
// name is swapped for a link meanwhile.
TEST(AtomicFile, WriterPathIsTheCreatedFile)
{
    fs::path dir = scratch("swap");
    std::ofstream(dir / "victim") << "precious";
    write_file_atomically(dir / "o.txt", [&](const fs::path& temporary) {
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.path().filename().string().rfind(".o.cambium-", 0) == 0) {
                fs::remove(entry.path());
                fs::create_symlink(dir / "victim", entry.path());
            }
        std::ofstream(temporary) << "written";
    });
    EXPECT_EQ(contents(dir / "victim"), "precious");
}

TEST(AtomicFile, FailureLeavesNothingAndKeepsTheOldFile)
{
    fs::path dir = scratch("fail");
    write_text(dir / "keep.txt", "old");
    EXPECT_THROW(write_file_atomically(dir / "keep.txt",
                                       [](const fs::path&) { throw Error("no"); }),
                 Error);
    EXPECT_EQ(contents(dir / "keep.txt"), "old");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
    try {
        write_text(dir / "missing" / "x.txt", "x");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("missing/x.txt: error: cannot be written"),
                  std::string::npos)
            << e.what();
    }
}

std::size_t entries(const fs::path& dir)
{
    return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// A private folder is fresh (never a planted one), owner-only, and gone afterwards
// with its contents; a link made inside is removed, not what it points to.
TEST(PrivateFolder, FreshOwnerOnlyAndRemoved)
{
    fs::path dir = scratch("private");
    fs::create_directories(dir / "outside");
    std::ofstream(dir / "outside" / "victim") << "precious";
    // The names a predictable scheme would give, planted as links to elsewhere.
    fs::create_directory_symlink(dir / "outside", dir / "v.mp4.frames");
    fs::create_directory_symlink(dir / "outside", dir / ".v.cambium-XXXXXX");
    fs::path first, second;
    {
        PrivateFolder a(dir / "v.mp4"), b(dir / "v.mp4");
        first = a.path();
        second = b.path();
        EXPECT_NE(first, second);
        EXPECT_EQ(first.parent_path(), dir);
        EXPECT_FALSE(fs::is_symlink(first));
        EXPECT_EQ(fs::status(first).permissions() & fs::perms::all, fs::perms::owner_all);
        EXPECT_EQ(entries(first), 0u);
        std::ofstream(first / "000001.png") << "frame";
        fs::create_symlink(dir / "outside" / "victim", first / "link.png");
        fs::create_directory_symlink(dir / "outside", first / "sub");
    }
    EXPECT_FALSE(fs::exists(first));
    EXPECT_FALSE(fs::exists(second));
    EXPECT_EQ(contents(dir / "outside" / "victim"), "precious");
    EXPECT_EQ(entries(dir / "outside"), 1u);
    EXPECT_EQ(entries(dir), 3u);  // outside and the two planted links, nothing else
}

// The result replaces a link planted at the target instead of writing through it.
TEST(PrivateFolder, MoveOntoReplacesALinkAtTheTarget)
{
    fs::path dir = scratch("private_move");
    std::ofstream(dir / "victim") << "precious";
    fs::create_symlink(dir / "victim", dir / "v.mp4");
    {
        PrivateFolder folder(dir / "v.mp4");
        std::ofstream(folder.path() / "encoded.mp4") << "video";
        folder.move_onto("encoded.mp4", dir / "v.mp4");
    }
    EXPECT_EQ(contents(dir / "victim"), "precious");
    EXPECT_FALSE(fs::is_symlink(dir / "v.mp4"));
    EXPECT_EQ(contents(dir / "v.mp4"), "video");
    EXPECT_EQ(entries(dir), 2u);
    EXPECT_THROW(PrivateFolder(dir / "missing" / "v.mp4"), Error);
}

}  // namespace
}  // namespace cambium
