// SPDX-License-Identifier: Apache-2.0
// Output files that appear whole or not at all, through a private temporary beside them.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace cambium {

/// Creates or replaces `file` atomically: `write` fills a fresh temporary in the same
/// folder, which is then renamed over `file`. The temporary is made with mkstemps
/// (O_CREAT|O_EXCL, a random name, never following a planted link) and `write` gets a
/// path that reaches that very file (/proc/self/fd/N where available), so nothing at a
/// predictable name is ever opened. `write` throws on failure; whatever goes wrong,
/// the temporary is removed and `file` is left as it was. Throws cambium::Error naming
/// `file`. The new file gets the usual permissions (0666 less the umask).
void write_file_atomically(const std::filesystem::path& file,
                           const std::function<void(const std::filesystem::path& temporary)>& write);

/// A fresh private folder beside `file` for work that ends in `file` (a video's frames
/// and encoding): made with mkdtemp (mode 0700, a random name that nothing planted can
/// take), removed with its contents on destruction, whatever way the caller leaves.
/// Throws cambium::Error naming `file`.
class PrivateFolder {
public:
    explicit PrivateFolder(const std::filesystem::path& file);
    ~PrivateFolder();
    PrivateFolder(PrivateFolder&& other) noexcept;
    PrivateFolder& operator=(PrivateFolder&&) = delete;
    PrivateFolder(const PrivateFolder&) = delete;
    PrivateFolder& operator=(const PrivateFolder&) = delete;

    const std::filesystem::path& path() const { return m_path; }
    /// Renames `name`, a file made inside the folder, over `file` in one step (a link
    /// at `file` is replaced, never followed). Throws cambium::Error naming `file`.
    void move_onto(const std::string& name, const std::filesystem::path& file) const;

private:
    std::filesystem::path m_path;
};

}  // namespace cambium
