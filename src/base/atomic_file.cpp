// SPDX-License-Identifier: Apache-2.0
// Output files that appear whole or not at all, through a private temporary beside them.
#include "base/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#include "base/diagnostics.h"

namespace cambium {

namespace {

/// The process's umask (read by setting it and putting it back).
mode_t current_umask()
{
    mode_t mask = ::umask(022);
    ::umask(mask);
    return mask;
}

/// The private temporary's mkstemp pattern beside `file`: a hidden name that keeps its
/// stem, then `extension` (image writers pick their format from it).
std::string temporary_pattern(const std::filesystem::path& file, const std::string& extension)
{
    // Appended piece by piece: GCC 12 reports a false -Wrestrict on "." + std::string.
    std::string name(1, '.');
    name += file.filename().stem().string();
    name += ".cambium-XXXXXX";
    return (file.parent_path() / (name + extension)).string();
}

[[noreturn]] void cannot_write(const std::filesystem::path& file)
{
    throw Error(FileLoc{file.string()}, std::string("cannot be written: ") + std::strerror(errno));
}

/// Removes the temporary unless released.
class TemporaryFile {
public:
    explicit TemporaryFile(const std::filesystem::path& file)
    {
        std::string extension = file.extension().string();
        std::string pattern = temporary_pattern(file, extension);
        m_fd = ::mkstemps(pattern.data(), int(extension.size()));
        if (m_fd < 0)
            cannot_write(file);
        ::fcntl(m_fd, F_SETFD, FD_CLOEXEC);
        m_path = pattern;
    }
    ~TemporaryFile()
    {
        if (m_fd >= 0)
            ::close(m_fd);
        if (!m_path.empty())
            ::unlink(m_path.c_str());
    }
    TemporaryFile(const TemporaryFile&) = delete;
    TemporaryFile& operator=(const TemporaryFile&) = delete;

    int fd() const { return m_fd; }
    const std::filesystem::path& path() const { return m_path; }
    /// The path writers open: the descriptor's own link when /proc is mounted, so a
    /// name swapped after mkstemps cannot redirect the writing.
    std::filesystem::path writable_path() const
    {
        std::filesystem::path link = "/proc/self/fd/" + std::to_string(m_fd);
        struct stat by_link {}, by_fd {};
        if (::stat(link.c_str(), &by_link) == 0 && ::fstat(m_fd, &by_fd) == 0 &&
            by_link.st_ino == by_fd.st_ino && by_link.st_dev == by_fd.st_dev)
            return link;
        return m_path;
    }
    void release()
    {
        ::close(m_fd);
        m_fd = -1;
        m_path.clear();
    }

private:
    int m_fd = -1;
    std::filesystem::path m_path;
};

}  // namespace

void write_file_atomically(const std::filesystem::path& file,
                           const std::function<void(const std::filesystem::path& temporary)>& write)
{
    TemporaryFile temporary(file);
    ::fchmod(temporary.fd(), 0666 & ~current_umask());
    write(temporary.writable_path());
    if (::rename(temporary.path().c_str(), file.c_str()) != 0)
        cannot_write(file);
    temporary.release();
}

PrivateFolder::PrivateFolder(const std::filesystem::path& file)
{
    std::string pattern = temporary_pattern(file, "");
    if (::mkdtemp(pattern.data()) == nullptr)
        cannot_write(file);
    m_path = pattern;
}

PrivateFolder::PrivateFolder(PrivateFolder&& other) noexcept : m_path(std::move(other.m_path))
{
    other.m_path.clear();
}

PrivateFolder::~PrivateFolder()
{
    // remove_all deletes links it finds inside, never what they point to
    std::error_code ignored;
    if (!m_path.empty())
        std::filesystem::remove_all(m_path, ignored);
}

void PrivateFolder::move_onto(const std::string& name, const std::filesystem::path& file) const
{
    if (::rename((m_path / name).c_str(), file.c_str()) != 0)
        cannot_write(file);
}

}  // namespace cambium
