// SPDX-License-Identifier: Apache-2.0
// Output files that appear whole or not at all, through a private temporary beside them.
#include "base/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

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

/// Removes the temporary unless released.
class TemporaryFile {
public:
    explicit TemporaryFile(const std::filesystem::path& file)
    {
        // A hidden name beside the file, keeping its extension (image writers pick
        // their format from it).
        // Appended piece by piece: GCC 12 reports a false -Wrestrict on "." + std::string.
        std::string name(1, '.');
        name += file.filename().stem().string();
        name += ".cambium-XXXXXX";
        std::string extension = file.extension().string();
        std::string pattern = (file.parent_path() / (name + extension)).string();
        m_fd = ::mkstemps(pattern.data(), int(extension.size()));
        if (m_fd < 0)
            throw Error(FileLoc{file.string()},
                        std::string("cannot be written: ") + std::strerror(errno));
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
        throw Error(FileLoc{file.string()},
                    std::string("cannot be written: ") + std::strerror(errno));
    temporary.release();
}

}  // namespace cambium
