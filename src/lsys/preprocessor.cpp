// SPDX-License-Identifier: Apache-2.0
// Runs an L-system file through the system C preprocessor, keeping cpfg's tab and `#(` lines.
#include "lsys/preprocessor.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "base/diagnostics.h"

namespace cambium::lsys {

namespace {

constexpr std::string_view tab_marker = "cambium_tab_";
constexpr std::string_view hash_marker = "cambium_hash_";

/// Quotes one word for /bin/sh.
std::string shell_quote(std::string_view word)
{
    std::string out = "'";
    for (char c : word) {
        if (c == '\'')
            out += "'\\''";
        else
            out += c;
    }
    return out + "'";
}

std::string read_file(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void write_file(const std::filesystem::path& path, std::string_view text)
{
    std::ofstream out(path, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out)
        throw Error("cannot write temporary file " + path.string());
}

/// Replaces every occurrence of `from` in `text` by `to`.
std::string replace_all(const std::string& text, std::string_view from, std::string_view to)
{
    std::string out;
    out.reserve(text.size());
    std::size_t pos = 0;
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, pos)) {
        out.append(text, pos, at - pos);
        out.append(to);
        pos = at + from.size();
    }
    out.append(text, pos, std::string::npos);
    return out;
}

/// A private temporary folder, removed with its contents on destruction.
class TempDir {
public:
    TempDir()
    {
        std::string pattern = (std::filesystem::temp_directory_path() / "cambium-XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw Error("cannot create a temporary folder in " + pattern);
        m_path = pattern;
    }
    ~TempDir()
    {
        std::error_code ec;
        std::filesystem::remove_all(m_path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return m_path; }

private:
    std::filesystem::path m_path;
};

std::string build_command(const PreprocessOptions& options, const TempDir& dir)
{
    std::string cmd = shell_quote(options.preprocessor);
    cmd.append(" -undef -x c -fno-dollars-in-identifiers");
    auto add = [&cmd](std::string_view flag, const std::string& value) {
        cmd.append(flag);
        cmd.append(shell_quote(value));
    };
    for (const auto& inc : options.include_dirs)
        add(" -I", inc.string());
    for (const auto& def : options.defines)
        add(" -D", def);
    add(" ", (dir.path() / "input.l").string());
    add(" >", (dir.path() / "out").string());
    add(" 2>", (dir.path() / "err").string());
    return cmd;
}

/// Forwards cpp's warnings (if any) with the temporary name replaced.
void forward_messages(const std::string& messages)
{
    std::istringstream lines(messages);
    std::string line;
    while (std::getline(lines, line))
        if (line.find("warning:") != std::string::npos)
            warn(line);
}

}  // namespace

std::string protect_cpfg_lines(std::string_view source)
{
    std::string out;
    out.reserve(source.size() + source.size() / 8);
    std::size_t pos = 0;
    while (pos < source.size()) {
        std::size_t eol = source.find('\n', pos);
        std::string_view line = source.substr(pos, eol == std::string_view::npos ? eol : eol - pos + 1);
        pos += line.size();
        std::size_t first = line.find_first_not_of(" \t");
        bool turtle_hash = first != std::string_view::npos && line.substr(first, 2) == "#(";
        if (!line.empty() && line[0] == '\t') {
            out += tab_marker;
            out += ' ';
            line.remove_prefix(1);
            if (first != std::string_view::npos)
                --first;
        }
        if (turtle_hash) {
            out += line.substr(0, first);
            out += hash_marker;
            out += line.substr(first + 1);
        } else {
            out += line;
        }
    }
    return out;
}

std::string restore_cpfg_lines(std::string_view text)
{
    std::string out;
    out.reserve(text.size());
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t eol = text.find('\n', pos);
        std::string_view line = text.substr(pos, eol == std::string_view::npos ? eol : eol - pos + 1);
        pos += line.size();
        std::size_t first = line.find_first_not_of(" \t");
        std::string restored(line);
        if (first != std::string_view::npos && line.substr(first, tab_marker.size()) == tab_marker) {
            std::size_t end = first + tab_marker.size();
            if (end < line.size() && line[end] == ' ')
                ++end;
            restored.assign(1, '\t');
            restored.append(line.substr(end));
        }
        restored = replace_all(std::move(restored), tab_marker, " ");
        out += replace_all(std::move(restored), hash_marker, "#");
    }
    return out;
}

std::string preprocess(std::string_view source, std::string_view file_name,
                       const PreprocessOptions& options)
{
    if (source.size() > options.max_input_bytes)
        throw Error(FileLoc{std::string(file_name), 0, 0},
                    "the file is " + std::to_string(source.size()) + " bytes; at most " +
                        std::to_string(options.max_input_bytes) + " are accepted");
    TempDir dir;
    std::string input_path = (dir.path() / "input.l").string();
    write_file(dir.path() / "input.l", protect_cpfg_lines(source));
    int status = std::system(build_command(options, dir).c_str());
    std::string messages = replace_all(read_file(dir.path() / "err"), input_path, file_name);
    if (status == -1 || !WIFEXITED(status))
        throw Error("cannot run the C preprocessor '" + options.preprocessor + "'");
    int code = WEXITSTATUS(status);
    if (code == 127)
        throw Error("the C preprocessor '" + options.preprocessor +
                    "' was not found; install cpp (e.g. apt-get install cpp) or pass another");
    if (code != 0)
        throw Error(FileLoc{std::string(file_name), 0, 0},
                    "the C preprocessor failed:\n" + messages);
    forward_messages(messages);
    std::string text = read_file(dir.path() / "out");
    return restore_cpfg_lines(replace_all(std::move(text), input_path, file_name));
}

}  // namespace cambium::lsys
