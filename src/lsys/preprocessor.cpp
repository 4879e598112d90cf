// SPDX-License-Identifier: Apache-2.0
// Runs an L-system file through the system C preprocessor, keeping cpfg's tab and `#(` lines.
#include "lsys/preprocessor.h"

#include <sys/stat.h>

#include <cctype>
#include <fstream>
#include <set>
#include <sstream>

#include "base/confinement.h"
#include "base/diagnostics.h"
#include "base/subprocess.h"

namespace cambium::lsys {

namespace {

constexpr std::string_view tab_marker = "cambium_tab_";
constexpr std::string_view hash_marker = "cambium_hash_";
constexpr std::size_t max_scanned_includes = 1000;

/// Calls `f` with each line of `text`, its '\n' included (the last one may lack it).
template <class F>
void for_each_line(std::string_view text, F f)
{
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t eol = text.find('\n', pos);
        std::string_view line = text.substr(pos, eol == std::string_view::npos ? eol : eol - pos + 1);
        pos += line.size();
        f(line);
    }
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

/// One `#include "name"` / `#include <name>` directive found by scan_includes.
struct IncludeDirective {
    std::string name;
    bool quoted = true;
    int line = 0, column = 0;
};

/// The include directives of `text` whose file name is written out (a computed
/// `#include MACRO` is left to cpp and its limits). Lines starting with a tab are skipped
/// when `tab_lines_protected`: they are production continuations, never directives.
std::vector<IncludeDirective> scan_includes(std::string_view text, bool tab_lines_protected)
{
    std::vector<IncludeDirective> found;
    int line = 0;
    for_each_line(text, [&](std::string_view l) {
        ++line;
        if (!l.empty() && l.back() == '\n')
            l.remove_suffix(1);
        if (tab_lines_protected && !l.empty() && l[0] == '\t')
            return;
        std::size_t i = l.find_first_not_of(" \t");
        if (i == std::string_view::npos || l[i] != '#')
            return;
        int column = int(i) + 1;
        i = l.find_first_not_of(" \t", i + 1);
        if (i == std::string_view::npos)
            return;
        std::string_view rest = l.substr(i);
        std::size_t word = 0;
        for (std::string_view w : {"include_next", "include", "import"})
            if (rest.substr(0, w.size()) == w) {
                word = w.size();
                break;
            }
        if (word == 0)
            return;
        i = l.find_first_not_of(" \t", i + word);
        if (i == std::string_view::npos || (l[i] != '"' && l[i] != '<'))
            return;
        char close = l[i] == '"' ? '"' : '>';
        std::size_t end = l.find(close, i + 1);
        if (end == std::string_view::npos)
            return;
        found.push_back({std::string(l.substr(i + 1, end - i - 1)), close == '"', line, column});
    });
    return found;
}

/// Refuses `__has_include`, `__has_include_next` and `GCC dependency` (a pragma, or the
/// text of a `_Pragma`) in `text`: cpp would look up the files they name, so a model could
/// learn which files exist outside its folder. Token pasting in a #define, which could
/// build the name, is refused too. Line splices are joined first, as cpp does.
void refuse_file_probes(std::string_view text, const std::string& file_name)
{
    // where `text` (one logical line) probes for a file, or npos; the word found in `word`
    auto find_probe = [](std::string_view text, std::string& word) {
        std::size_t at = text.find("__has_include");
        for (std::size_t gcc = text.find("GCC"); gcc != std::string_view::npos && gcc < at;
             gcc = text.find("GCC", gcc + 1)) {
            std::size_t next = text.find_first_not_of(" \t", gcc + 3);
            if (next > gcc + 3 && next != std::string_view::npos &&
                text.substr(next, 10) == "dependency") {
                word = "GCC dependency";
                return gcc;
            }
        }
        if (at != std::string_view::npos) {
            word = text.substr(at, 18) == "__has_include_next" ? "__has_include_next" : "__has_include";
            return at;
        }
        // a macro that pastes tokens could build __has_include where no scan sees it
        std::size_t hash = text.find_first_not_of(" \t");
        if (hash == std::string_view::npos)
            return hash;
        std::size_t name = text.substr(hash, 1) == "#" ? hash + 1 : text.substr(hash, 2) == "%:" ? hash + 2 : hash;
        name = text.find_first_not_of(" \t", name);
        if (name == hash || name == std::string_view::npos || text.substr(name, 6) != "define")
            return std::string_view::npos;
        at = std::min(text.find("##", name), text.find("%:%:", name));
        if (at != std::string_view::npos)
            word = "token pasting in a #define";
        return at;
    };
    std::string joined;
    int line = 0, first = 1;
    for_each_line(text, [&](std::string_view l) {
        ++line;
        if (joined.empty())
            first = line;
        if (!l.empty() && l.back() == '\n')
            l.remove_suffix(1);
        if (!l.empty() && l.back() == '\r')
            l.remove_suffix(1);
        if (!l.empty() && l.back() == '\\') {
            joined.append(l.substr(0, l.size() - 1));
            return;
        }
        joined.append(l);
        std::string word;
        if (std::size_t at = find_probe(joined, word); at != std::string_view::npos)
            throw Error(FileLoc{file_name, first, int(at) + 1},
                        "'" + word + "' would tell the model whether a file exists outside its "
                                     "folder; --allow-file-access lifts this");
        joined.clear();
    });
}

/// Refuses, before cpp opens them, included names that are not regular files (reading
/// /dev/zero, a FIFO or a terminal never ends) or that lie outside `confine_to`.
/// Follows the includes it can resolve (as cpp: the including file's folder for quoted
/// names, then the -I folders).
void check_includes(std::string_view source, const std::string& file_name,
                    const std::filesystem::path& folder,
                    const std::vector<std::filesystem::path>& include_dirs,
                    const std::optional<std::filesystem::path>& confine_to)
{
    struct Pending {
        std::string text;
        std::string name;
        std::filesystem::path folder;
        bool protected_tabs;
    };
    std::vector<Pending> queue{{std::string(source), file_name, folder, true}};
    std::set<std::filesystem::path> seen;
    while (!queue.empty()) {
        Pending current = std::move(queue.back());
        queue.pop_back();
        if (confine_to)
            refuse_file_probes(current.text, current.name);
        for (const IncludeDirective& d : scan_includes(current.text, current.protected_tabs)) {
            std::vector<std::filesystem::path> candidates;
            std::filesystem::path named(d.name);
            if (named.is_absolute()) {
                candidates.push_back(named);
            } else {
                if (d.quoted)
                    candidates.push_back(current.folder / named);
                for (const auto& dir : include_dirs)
                    candidates.push_back(dir / named);
            }
            for (const auto& candidate : candidates) {
                struct stat st {};
                if (::stat(candidate.c_str(), &st) != 0)
                    continue;  // not there: the next folder, or cpp's own error
                if (!S_ISREG(st.st_mode))
                    throw Error(FileLoc{current.name, d.line, d.column},
                                "#include names " + candidate.string() +
                                    ", which is a device, FIFO or folder, not a file");
                if (confine_to && !lies_within(candidate, *confine_to))
                    throw Error(FileLoc{current.name, d.line, d.column},
                                "#include names " + candidate.string() +
                                    ", which lies outside the model's folder " +
                                    confine_to->string() + " (--allow-file-access lifts this)");
                std::error_code ec;
                auto canonical = std::filesystem::weakly_canonical(candidate, ec);
                if (!seen.insert(ec ? candidate : canonical).second)
                    break;
                if (seen.size() > max_scanned_includes)
                    throw Error(FileLoc{current.name, d.line, d.column},
                                "more than " + std::to_string(max_scanned_includes) +
                                    " files are included");
                // Only the start of a huge file is scanned; cpp's output limit does the rest.
                std::string text(std::min<std::size_t>(std::size_t(st.st_size), 16u << 20), '\0');
                std::ifstream in(candidate, std::ios::binary);
                in.read(text.data(), std::streamsize(text.size()));
                text.resize(std::size_t(in.gcount()));
                queue.push_back({std::move(text), candidate.string(), candidate.parent_path(), false});
                break;
            }
        }
    }
}

/// Refuses cpp's output when its line markers show it read a file outside `confine_to`:
/// an `#include MACRO` whose name check_includes could not see. cpp runs in `folder`,
/// so relative names are that folder's; `<built-in>` and the like name no file, and
/// the model's own file (`main_name`, as the user named it) was checked by its reader.
void check_included_files(const std::string& output, const std::filesystem::path& folder,
                          const std::filesystem::path& confine_to, const std::string& main_name)
{
    std::set<std::string> checked;
    for_each_line(output, [&](std::string_view line) {
        if (line.size() < 4 || line[0] != '#' || line[1] != ' ' ||
            !std::isdigit(static_cast<unsigned char>(line[2])))
            return;
        std::size_t open = line.find('"');
        if (open == std::string_view::npos)
            return;
        std::string name;
        for (std::size_t i = open + 1; i < line.size() && line[i] != '"'; ++i)
            name += line[i] == '\\' && i + 1 < line.size() ? line[++i] : line[i];
        if (name.empty() || name.front() == '<' || name == main_name || !checked.insert(name).second)
            return;
        std::filesystem::path file(name);
        if (!lies_within(file.is_absolute() ? file : folder / file, confine_to))
            throw Error(FileLoc{main_name, 0, 0},
                        "the C preprocessor read " + name + ", which lies outside the model's folder " +
                            confine_to.string() +
                            " (an #include whose name a macro computes?); --allow-file-access lifts this");
    });
}

/// `name` as a C string literal for a line marker.
std::string quoted(std::string_view name)
{
    std::string out = "\"";
    for (char c : name) {
        if (c == '"' || c == '\\')
            out += '\\';
        out += c == '\n' ? '?' : c;
    }
    return out + '"';
}

std::filesystem::path absolute_folder(const std::filesystem::path& folder)
{
    std::error_code ec;
    auto absolute = std::filesystem::absolute(folder.empty() ? "." : folder, ec);
    return ec ? folder : absolute.lexically_normal();
}

std::vector<std::string> cpp_command(const PreprocessOptions& options,
                                     const std::filesystem::path& folder)
{
    // -nostdinc: a model has no business with the system's C headers.
    std::vector<std::string> argv{options.preprocessor, "-undef", "-x", "c",
                                  "-fno-dollars-in-identifiers", "-nostdinc",
                                  "-I" + folder.string()};
    for (const auto& dir : options.include_dirs)
        if (!dir.empty())  // an empty -I would swallow the next word as a folder
            argv.push_back("-I" + absolute_folder(dir).string());
    for (const auto& def : options.defines)
        argv.push_back("-D" + def);
    argv.emplace_back("-");  // the protected text, on a pipe
    return argv;
}

/// Relays cpp's warnings (if any).
void forward_messages(const std::string& messages)
{
    std::istringstream lines(messages);
    std::string line;
    while (std::getline(lines, line))
        if (line.find("warning:") != std::string::npos)
            warn(line);
}

std::string fmt_seconds(double seconds)
{
    std::ostringstream out;
    out << seconds;
    return out.str();
}

/// cpp runs in the model's folder, so it names included files relative to it
/// ("leaf.l"); the user named the model from their own folder. Prefixes `folder` (as
/// the user gave it) to a relative file name at the start of each message line, after
/// "included from ", and in line markers (`# 3 "leaf.l" 1`), so errors name the file
/// the user can open. The main file (named by its marker) is left alone.
std::string name_from_user_folder(const std::string& text, const std::filesystem::path& folder,
                                  const std::string& main_name)
{
    if (folder.empty() || folder == ".")
        return text;
    auto rename = [&](std::string_view name) {
        std::filesystem::path p(name);
        std::error_code ec;
        if (name.empty() || name == main_name || name.front() == '<' || p.is_absolute() ||
            !std::filesystem::is_regular_file(folder / p, ec))  // not a file name ("cc1")
            return std::string(name);
        return (folder / p).string();
    };
    std::string out;
    out.reserve(text.size());
    for_each_line(text, [&](std::string_view view) {
        std::string line(view);
        std::size_t open = std::string::npos, close = std::string::npos;
        if (line.size() > 2 && line[0] == '#' && line[1] == ' ' &&
            std::isdigit(static_cast<unsigned char>(line[2]))) {  // a line marker
            open = line.find('"');
            close = open == std::string::npos ? open : line.find('"', open + 1);
            if (close != std::string::npos)
                ++open;
        } else {
            constexpr std::string_view from = "included from ";
            std::size_t at = line.find(from);
            open = at == std::string::npos ? 0 : at + from.size();
            close = line.find(':', open);
        }
        if (open != std::string::npos && close != std::string::npos && close > open)
            line = line.substr(0, open) + rename(std::string_view(line).substr(open, close - open)) +
                   line.substr(close);
        out += line;
    });
    return out;
}

std::string megabytes(std::size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

/// Whether cpp (the default one, without -D) would give `source` back unchanged but for
/// whitespace and line markers: no directive, comment, line splice, character or string
/// literal, trigraph, or name of cpp's own (__LINE__). Such a file is parsed as it is:
/// starting cpp costs more than deriving a small model (build/benchmarks/derive).
bool needs_no_preprocessing(std::string_view source, const PreprocessOptions& options)
{
    if (options.preprocessor != "cpp" || !options.defines.empty())
        return false;
    if (source.find_first_of("#/\\'\"\r\f\v") != std::string_view::npos)
        return false;
    return source.find("??") == std::string_view::npos &&
           source.find("__") == std::string_view::npos;
}

}  // namespace

std::string protect_cpfg_lines(std::string_view source)
{
    std::string out;
    out.reserve(source.size() + source.size() / 8);
    for_each_line(source, [&](std::string_view line) {
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
    });
    return out;
}

std::string restore_cpfg_lines(std::string_view text)
{
    std::string out;
    out.reserve(text.size());
    for_each_line(text, [&](std::string_view line) {
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
    });
    return out;
}

std::string preprocess(std::string_view source, std::string_view file_name,
                       const PreprocessOptions& options)
{
    const std::string name(file_name);
    if (source.size() > options.max_input_bytes)
        throw Error(FileLoc{name, 0, 0},
                    "the file is " + std::to_string(source.size()) + " bytes; at most " +
                        std::to_string(options.max_input_bytes) + " are accepted");
    if (needs_no_preprocessing(source, options))
        return "# 1 " + quoted(file_name) + "\n" + std::string(source);
    const std::filesystem::path folder = absolute_folder(options.folder);
    std::vector<std::filesystem::path> include_dirs{folder};  // as cpp_command's -I list
    for (const auto& dir : options.include_dirs)
        if (!dir.empty())
            include_dirs.push_back(absolute_folder(dir));
    check_includes(source, name, folder, include_dirs, options.confine_to);

    // The line marker makes cpp's messages and markers name the model's file.
    std::string input = "# 1 " + quoted(file_name) + "\n" + protect_cpfg_lines(source);
    ProcessLimits limits;
    limits.wall_seconds = options.max_seconds;
    limits.max_output_bytes = options.max_output_bytes;
    limits.max_memory_bytes = options.max_memory_bytes;
    ProcessIo io;
    io.input = input;
    ProcessResult r = run_process(cpp_command(options, folder), folder, io, limits);
    std::string messages =
        name_from_user_folder(replace_all(r.messages, "<stdin>", name), options.folder, name);
    while (!messages.empty() && (messages.back() == '\n' || messages.front() == '\n'))
        messages.erase(messages.back() == '\n' ? messages.size() - 1 : 0, 1);
    switch (r.end) {
    case ProcessResult::End::not_found:
        throw Error("the C preprocessor '" + options.preprocessor + "' was not found (" +
                    r.messages + "); install cpp (e.g. apt-get install cpp) or pass another with -P");
    case ProcessResult::End::timed_out:
        throw Error(FileLoc{name, 0, 0},
                    "the C preprocessor was stopped after " +
                        fmt_seconds(options.max_seconds) +
                        " s (does an #include read something endless?)");
    case ProcessResult::End::output_too_large:
        throw Error(FileLoc{name, 0, 0},
                    "the preprocessed text grew past " + megabytes(options.max_output_bytes) +
                        " and the C preprocessor was stopped (a macro that expands without bound?)");
    case ProcessResult::End::signalled:
        throw Error(FileLoc{name, 0, 0}, "the C preprocessor crashed (exit status " +
                                             std::to_string(r.exit_code) + "):\n" + messages);
    case ProcessResult::End::exited:
        break;
    }
    if (r.exit_code != 0)
        throw Error(FileLoc{name, 0, 0}, "the C preprocessor failed:\n" + messages);
    if (options.confine_to)
        check_included_files(r.output, folder, *options.confine_to, name);
    forward_messages(messages);
    std::string text = replace_all(r.output, "\"<stdin>\"", quoted(file_name));
    return restore_cpfg_lines(name_from_user_folder(text, options.folder, name));
}

}  // namespace cambium::lsys
