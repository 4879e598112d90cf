// SPDX-License-Identifier: Apache-2.0
// Bounded reads of regular files.
#include "base/input_file.h"

#include <fstream>

#include "base/diagnostics.h"

namespace cambium {

std::uintmax_t regular_file_size(const std::filesystem::path& file, const char* what,
                                 std::uintmax_t max_bytes)
{
    std::error_code ec;
    std::filesystem::file_status status = std::filesystem::status(file, ec);
    if (!std::filesystem::exists(status))
        throw Error(FileLoc{file.string()}, std::string("cannot open ") + what + ": no such file");
    if (!std::filesystem::is_regular_file(status))
        throw Error(FileLoc{file.string()}, std::string("cannot open ") + what +
                                                ": not a regular file (a folder, FIFO or device)");
    std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (ec)
        throw Error(FileLoc{file.string()}, std::string("cannot read ") + what);
    if (size > max_bytes)
        throw Error(FileLoc{file.string()}, std::string(what) + " is too large (" +
                                                std::to_string(size) + " bytes; the limit is " +
                                                std::to_string(max_bytes) + ")");
    return size;
}

std::string read_file(const std::filesystem::path& file, const char* what, std::uintmax_t max_bytes)
{
    std::uintmax_t size = regular_file_size(file, what, max_bytes);
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw Error(FileLoc{file.string()}, std::string("cannot open ") + what);
    // the size checked, not whatever the file grows to meanwhile
    std::string text(static_cast<std::size_t>(size), '\0');
    in.read(text.data(), static_cast<std::streamsize>(size));
    text.resize(static_cast<std::size_t>(in.gcount()));
    return text;
}

std::vector<unsigned char> read_binary_file(const std::filesystem::path& file, const char* what,
                                            std::uintmax_t max_bytes)
{
    std::uintmax_t size = regular_file_size(file, what, max_bytes);
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw Error(FileLoc{file.string()}, std::string("cannot open ") + what);
    std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (!in)
        throw Error(FileLoc{file.string()}, std::string("cannot read ") + what);
    return bytes;
}

}  // namespace cambium
