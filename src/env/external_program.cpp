// SPDX-License-Identifier: Apache-2.0
// External environmental programs: cpfg's pipe protocol, as programs built with vlab's
// communication library expect it, with every wait bounded.
#include "env/external_program.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string_view>

#include "base/atomic_file.h"
#include "base/subprocess.h"
#include "geom/text_input.h"

namespace cambium::env {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// the flag of a `Control:` line (vlab's communication.h)
constexpr int first_chunk = 1;
constexpr int last_chunk = 4;
constexpr int process_exit = 8;
constexpr int default_queries_per_chunk = 100;  // cpfg's chunk through pipes

std::string printf_double(const char* format, double a, double b = 0, double c = 0)
{
    // formats are checked when read: only %f %e %g %a conversions, at most three
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
    const int n = std::snprintf(nullptr, 0, format, a, b, c);
    std::string text(std::size_t(std::max(n, 0)), '\0');
    std::snprintf(text.data(), text.size() + 1, format, a, b, c);
#pragma GCC diagnostic pop
    return text;
}

void append_module(std::string& out, const SentModule& m, bool communication)
{
    out += communication ? "E" : m.symbol;  // cpfg names the ?E module "E"
    if (m.params.empty())
        return;
    out += '(';
    for (std::size_t k = 0; k < m.params.size(); ++k) {
        if (k > 0)
            out += ',';
        out += printf_double("%g", double(m.params[k]));
    }
    out += ')';
}

void append_turtle(std::string& out, const std::optional<TurtleFormat>& format, const SentVector& v)
{
    if (!format)
        return;
    out += printf_double(format->format.c_str(), double(v.values[0]), double(v.values[1]),
                         double(v.values[2]));
    out += '\n';
}

/// One ?E as cpfg writes it: address, the module and the next one, the turtle lines.
void append_query(std::string& out, const Query& q, const CommSpec& spec)
{
    out += std::to_string(q.address);
    out += ' ';
    append_module(out, q.module, true);
    if (q.following && spec.following_module)
        append_module(out, *q.following, false);
    out += '\n';
    append_turtle(out, spec.position, q.position);
    append_turtle(out, spec.heading, q.heading);
    append_turtle(out, spec.left, q.left);
    append_turtle(out, spec.up, q.up);
    append_turtle(out, spec.line_width, q.line_width);
    append_turtle(out, spec.scale_factor, q.scale_factor);
    if (q.geometry) {
        // vlab's library reads the block between these two lines (DATA_BEGIN, DATA_END)
        out += "Dbegin\n";
        for (const std::string& statement : *q.geometry) {
            out += statement;
            out += '\n';
        }
        out += "Dend\n";
    }
}

/// A line the program wrote: an answer, the end of its answers, nothing, or garbage.
struct Line {
    enum class Kind { answer, control, blank, garbage } kind = Kind::garbage;
    Reply reply;
    int flag = 0;
    std::string why;  ///< for garbage
};

bool separator(char c) { return c == ' ' || c == ',' || c == ';' || c == ':'; }

/// Reads a line as cpfg's master reads it: `Control: flag`, or an address (digits, after
/// any of " ,;:") and then, anywhere after it, `E` with an optional parameter list where
/// an empty field leaves the parameter unchanged and a field is read with atof.
Line parse_line(std::string_view text)
{
    Line line;
    if (text.substr(0, 7) == "Control") {
        const std::string rest(text.substr(std::min<std::size_t>(8, text.size())));
        char* end = nullptr;
        const long flag = std::strtol(rest.c_str(), &end, 10);
        if (end == rest.c_str()) {
            line.why = "a 'Control:' line without its flag";
            return line;
        }
        line.kind = Line::Kind::control;
        line.flag = int(flag);
        return line;
    }
    std::size_t i = 0;
    while (i < text.size() && separator(text[i])) ++i;
    if (i == text.size()) {
        line.kind = Line::Kind::blank;
        return line;
    }
    const std::size_t digits = i;
    std::uint64_t address = 0;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
        if (address > (UINT64_MAX - 9) / 10) {
            line.why = "an address too large";
            return line;
        }
        address = address * 10 + std::uint64_t(text[i++] - '0');
    }
    if (i == digits) {
        line.why = "a line that does not begin with an address";
        return line;
    }
    while (i < text.size() && !separator(text[i]))
        ++i;  // the rest of the address's token, as sscanf("%lu") leaves it
    const std::size_t e = text.find('E', i);
    if (e == std::string_view::npos) {
        line.why = "an answer without the module E";
        return line;
    }
    line.reply.address = address;
    if (e + 1 < text.size() && text[e + 1] == '(') {
        const std::size_t close = text.find(')', e + 2);
        if (close == std::string_view::npos) {
            line.why = "an answer without the closing parenthesis of E(...)";
            return line;
        }
        std::string_view fields = text.substr(e + 2, close - e - 2);
        for (;;) {
            const std::size_t comma = fields.find(',');
            const std::string field(fields.substr(0, comma));
            if (field.empty())
                line.reply.params.emplace_back(std::nullopt);
            else
                line.reply.params.emplace_back(float(std::atof(field.c_str())));
            if (comma == std::string_view::npos)
                break;
            fields.remove_prefix(comma + 1);
        }
    }
    line.kind = Line::Kind::answer;
    return line;
}

/// A file in a message folder, created for this pass only (never through a link); false
/// when the name is taken.
bool write_private_file(const fs::path& path, const std::string& text)
{
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0 && errno == EEXIST)
        return false;
    if (fd < 0)
        throw Error("cannot create '" + path.string() + "': " + std::strerror(errno));
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t w = ::write(fd, text.data() + done, text.size() - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            const int error = errno;
            ::close(fd);
            throw Error("cannot write '" + path.string() + "': " + std::strerror(error));
        }
        done += std::size_t(w);
    }
    if (::close(fd) != 0)
        throw Error("cannot write '" + path.string() + "': " + std::strerror(errno));
    return true;
}

/// An Error's text without its "error: " prefix, to be wrapped in another.
std::string message_of(const Error& e)
{
    std::string text = e.what();
    if (text.rfind("error: ", 0) == 0)
        text.erase(0, 7);
    return text;
}

bool is_real_directory(const fs::path& folder)
{
    std::error_code ec;
    return fs::symlink_status(folder, ec).type() == fs::file_type::directory;
}

/// A private copy of a `.e` file whose `communication type:` says pipes: vlab's library
/// takes the type from the file it is given, so a files, memory or sockets `.e` makes it
/// speak pipes this way. The folder and copy are removed on destruction.
class PipesCopy {
public:
    explicit PipesCopy(const CommSpec& spec)
    {
        std::string text = geom::read_text_file(spec.file, "communication specification file");
        std::string out;
        std::size_t begin = 0;
        while (begin < text.size()) {
            std::size_t end = text.find('\n', begin);
            end = end == std::string::npos ? text.size() : end + 1;
            const std::string_view line(text.data() + begin, end - begin);
            const std::size_t colon = line.find(':');
            if (colon != std::string_view::npos &&
                geom::normalize_command_name(line.substr(0, colon)) == "communication type") {
                out += "communication type: pipes";
                if (spec.queries_per_chunk > 0) {
                    out += ' ';
                    out += std::to_string(spec.queries_per_chunk);
                }
                out += '\n';
            } else {
                out.append(line);
            }
            begin = end;
        }
        m_folder = std::make_unique<PrivateFolder>(fs::temp_directory_path() / spec.file.filename());
        m_file = m_folder->path() / spec.file.filename();
        if (!write_private_file(m_file, out))
            throw Error("'" + m_file.string() + "' exists");
    }
    const fs::path& file() const { return m_file; }

private:
    std::unique_ptr<PrivateFolder> m_folder;  ///< removed with the copy when this goes
    fs::path m_file;
};

class ExternalProgram final : public Environment {
public:
    ExternalProgram(const CommSpec& spec, const Context& context, const ExternalLimits& limits)
        : m_spec(spec), m_limits(limits), m_name(spec.executable.front())
    {
        if (spec.communication_type != "pipes")
            m_copy = std::make_unique<PipesCopy>(spec);
        std::vector<std::string> argv{
            spec.executable.front(), "-e",
            m_copy ? m_copy->file().string() : spec_argument(spec, context)};
        argv.insert(argv.end(), spec.executable.begin() + 1, spec.executable.end());
        if (argv.size() > 3 && argv.back() == "&")
            argv.pop_back();  // cpfg drops a trailing '&' (its system() background)
        ProcessLimits process;
        process.max_memory_bytes = limits.max_memory_bytes;
        try {
            m_process = std::make_unique<Coprocess>(argv, context.folder, process);
        } catch (const Interrupted&) {
            throw;
        } catch (const Error& e) {
            throw Error(spec.executable_loc, message_of(e) + " (the environmental program of " +
                                                 spec.file.string() + ")");
        }
        start();
    }

    ~ExternalProgram() override
    {
        if (!m_failed && std::uncaught_exceptions() == 0) {
            try {
                goodbye();
            } catch (const Interrupted& e) {
                m_process->kill();
                std::raise(
                    e.signal());  // handlers are restored: the signal ends cambium as it would
            } catch (...) {
            }
        }
        m_process->kill();
    }

    std::vector<Reply> pass(const std::vector<Query>& queries, int step) override
    {
        if (m_failed)
            throw error("failed before and is not asked again");
        std::vector<Reply> replies;
        if (queries.empty())
            return replies;  // cpfg sends nothing for a string without ?E
        m_step = step;
        m_pass_bytes = 0;
        m_sent_log.clear();
        m_received_log.clear();
        try {
            const std::size_t chunk = m_spec.queries_per_chunk > 0
                                          ? std::size_t(m_spec.queries_per_chunk)
                                          : default_queries_per_chunk;
            const auto deadline = Clock::now() + seconds(m_limits.seconds_per_pass);
            std::string message;
            for (std::size_t begin = 0; begin < queries.size(); begin += chunk) {
                const std::size_t end = std::min(queries.size(), begin + chunk);
                const bool last = end == queries.size();
                message.clear();
                for (std::size_t k = begin; k < end; ++k) append_query(message, queries[k], m_spec);
                const int flag = (begin == 0 ? first_chunk : 0) | (last ? last_chunk : 0);
                // a chunk that is not the last carries step 0, as in cpfg
                message += "Control: " + std::to_string(flag) + " " +
                           std::to_string(last ? step : 0) + "\n";
                exchange(message, deadline, replies, queries.size());
            }
        } catch (...) {
            fail();
            write_log(false);
            throw;
        }
        write_log(true);
        return replies;
    }

private:
    static Clock::duration seconds(double s)
    {
        return std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double>(s > 0 ? s : 1e9));
    }

    /// The `.e` file as the program is told it: relative to the model folder when inside it.
    static std::string spec_argument(const CommSpec& spec, const Context& context)
    {
        std::error_code ec;
        const fs::path file = fs::absolute(spec.file, ec);
        const fs::path folder =
            fs::absolute(context.folder.empty() ? fs::path(".") : context.folder, ec);
        const fs::path relative =
            file.lexically_normal().lexically_relative(folder.lexically_normal());
        if (!relative.empty() && *relative.begin() != "..")
            return relative.string();
        return file.string();
    }

    Error error(const std::string& what) const
    {
        return Error("environmental program '" + m_name + "' (" + m_spec.file.string() +
                     "): " + what);
    }

    /// The program's end for a message: how it exited, when it has.
    std::string end_of_program()
    {
        const std::string how = m_process->end_description(std::chrono::milliseconds(200));
        return how == "is still running" ? std::string() : " (it " + how + ")";
    }

    void fail()
    {
        m_failed = true;
        m_process->kill();
    }

    std::string step_text() const
    {
        return m_step < 0 ? std::string("at its start") : "at step " + std::to_string(m_step);
    }

    /// Reads what the program wrote into m_input (a bounded amount, so lines are taken
    /// between reads), within the line and pass limits.
    void read_available()
    {
        std::array<char, 65536> buffer;
        for (int reads = 0; reads < 16; ++reads) {
            const std::ptrdiff_t n = m_process->read_some(buffer.data(), buffer.size());
            if (n < 0)
                return;
            if (n == 0) {
                const std::string how = end_of_program();
                throw error("closed its output " + step_text() +
                            (how.empty() ? " (it is still running)" : how));
            }
            m_pass_bytes += std::size_t(n);
            m_input.append(buffer.data(), std::size_t(n));
            if (!m_limits.message_folder.empty())
                m_received_log.append(buffer.data(), std::size_t(n));
            if (m_limits.max_pass_bytes > 0 && m_pass_bytes > m_limits.max_pass_bytes)
                throw error("wrote more than " + std::to_string(m_limits.max_pass_bytes) +
                            " bytes " + step_text() + " (the limit of one pass)");
            const std::size_t last = m_input.rfind('\n');
            check_line_length(m_input.size() - (last == std::string::npos ? 0 : last + 1));
        }
    }

    void check_line_length(std::size_t length) const
    {
        if (m_limits.max_line_bytes > 0 && length > m_limits.max_line_bytes)
            throw error("wrote a line longer than " + std::to_string(m_limits.max_line_bytes) +
                        " bytes " + step_text());
    }

    /// Waits until the program wrote its start-up byte (1), as vlab's library sends it.
    void start()
    {
        m_step = -1;
        const auto deadline = Clock::now() + seconds(m_limits.seconds_per_pass);
        try {
            while (m_input.empty()) {
                const auto left =
                    std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
                if (left.count() <= 0)
                    throw error("did not send its start-up byte within " +
                                printf_double("%g", m_limits.seconds_per_pass) +
                                " s (is it built with vlab's communication library?)");
                if (m_process->wait(false, true, left).output)
                    read_available();
            }
            if (m_input.front() != '\x01')
                throw error(
                    "sent " +
                    printf_double("%g", double(static_cast<unsigned char>(m_input.front()))) +
                    " instead of its start-up byte 1 (is it built with vlab's communication "
                    "library?)");
            m_input.erase(0, 1);
        } catch (...) {
            fail();
            throw;
        }
    }

    /// Sends one chunk and reads the answers up to the program's `Control:` line with the
    /// last-chunk flag, reading while writing so an immediate answer cannot block both.
    void exchange(const std::string& message, Clock::time_point deadline,
                  std::vector<Reply>& replies, std::size_t most)
    {
        if (!m_limits.message_folder.empty())
            m_sent_log += message;
        std::size_t written = 0;
        for (;;) {
            if (take_lines(replies, most, written == message.size()))
                return;
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
            if (left.count() <= 0)
                throw error("did not answer within " +
                            printf_double("%g", m_limits.seconds_per_pass) + " s " + step_text() +
                            (written < message.size() ? " (it stopped reading its input)" : ""));
            const Coprocess::Ready ready = m_process->wait(written < message.size(), true, left);
            if (ready.input) {
                const std::ptrdiff_t w =
                    m_process->write_some(std::string_view(message).substr(written));
                if (w < 0)
                    throw error("stopped reading its input " + step_text() + end_of_program());
                written += std::size_t(w);
            }
            if (ready.output)
                read_available();
        }
    }

    /// Takes the complete lines read; true at the `Control:` line that ends the answers.
    bool take_lines(std::vector<Reply>& replies, std::size_t most, bool all_written)
    {
        std::size_t begin = 0;
        bool ended = false;
        for (std::size_t newline;
             !ended && (newline = m_input.find('\n', begin)) != std::string::npos;
             begin = newline + 1) {
            std::string_view text(m_input.data() + begin, newline - begin);
            check_line_length(text.size());
            if (!text.empty() && text.back() == '\r')
                text.remove_suffix(1);
            Line line = parse_line(text);
            switch (line.kind) {
                case Line::Kind::blank: break;
                case Line::Kind::garbage:
                    throw error("answered '" + printable(text) + "' " + step_text() + ": " +
                                line.why);
                case Line::Kind::control:
                    if (line.flag & last_chunk) {
                        if (!all_written)
                            throw error("ended its answers before reading the whole message " +
                                        step_text());
                        ended = true;
                    }
                    break;
                case Line::Kind::answer:
                    if (replies.size() >= most)
                        throw error("answered more often than the " + std::to_string(most) +
                                    " ?E modules sent " + step_text());
                    replies.push_back(std::move(line.reply));
                    break;
            }
        }
        m_input.erase(0, begin);  // what follows the end stays for the next pass, as in cpfg
        return ended;
    }

    static std::string printable(std::string_view text)
    {
        std::string out;
        for (char c : text.substr(0, 80))
            out += (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) >= 127)
                       ? '?'
                       : c;
        if (text.size() > 80)
            out += "...";
        return out;
    }

    /// The pass's messages, when a message folder is given; `strict` reports a failure.
    void write_log(bool strict)
    {
        if (m_limits.message_folder.empty())
            return;
        try {
            char name[32];
            std::snprintf(name, sizeof name, "step%03d", m_step);
            // a step seen again (another run, the same step) gets a number of its own
            for (int k = 1;; ++k) {
                const std::string base =
                    (m_limits.message_folder / name).string() + (k > 1 ? "-" + std::to_string(k) : "");
                if (!write_private_file(base + ".to", m_sent_log))
                    continue;
                if (!write_private_file(base + ".from", m_received_log))
                    throw Error("'" + base + ".from' exists");
                break;
            }
        } catch (const Error& e) {
            if (strict)
                throw error("message log: " + message_of(e));
        }
    }

    void goodbye()
    {
        // cpfg's last message; a library program answers with its end of answers, 1 and exits
        const std::string message = "Control: " + std::to_string(process_exit) + " 0\n";
        const auto deadline = Clock::now() + seconds(m_limits.seconds_per_pass);
        std::size_t written = 0, read = 0;
        std::array<char, 4096> buffer;
        for (;;) {
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
            if (left.count() <= 0)
                return;
            const Coprocess::Ready ready = m_process->wait(written < message.size(), true, left);
            if (ready.input) {
                const std::ptrdiff_t w =
                    m_process->write_some(std::string_view(message).substr(written));
                if (w < 0)
                    return;
                written += std::size_t(w);
                if (written == message.size())
                    m_process->close_input();
            }
            if (ready.output) {
                const std::ptrdiff_t n = m_process->read_some(buffer.data(), buffer.size());
                if (n == 0)
                    return;  // it exited (or closed its output): done
                if (n > 0 && (read += std::size_t(n)) > m_limits.max_line_bytes)
                    return;
            }
        }
    }

    CommSpec m_spec;
    ExternalLimits m_limits;
    std::string m_name;
    std::unique_ptr<PipesCopy> m_copy;  ///< declared before m_process: removed after it ends
    std::unique_ptr<Coprocess> m_process;
    std::string m_input;  ///< read and not yet taken (a partial line)
    std::string m_sent_log, m_received_log;
    std::size_t m_pass_bytes = 0;
    int m_step = -1;
    bool m_failed = false;
};

}  // namespace

std::unique_ptr<Environment> make_external_program(const CommSpec& spec, const Context& context,
                                                   const ExternalLimits& limits)
{
    if (spec.executable.empty())
        throw Error(FileLoc{spec.file.string()},
                    "no 'executable:' line names the environmental program");
    if (!limits.message_folder.empty() && !is_real_directory(limits.message_folder))
        throw Error("message folder '" + limits.message_folder.string() + "' is not a directory");
    return std::make_unique<ExternalProgram>(spec, context, limits);
}

void prepare_message_folder(const fs::path& folder)
{
    if (::mkdir(folder.c_str(), 0700) == 0)
        return;
    if (errno != EEXIST)
        throw Error("cannot create the message folder '" + folder.string() +
                    "': " + std::strerror(errno));
    if (!is_real_directory(folder))
        throw Error("the message folder '" + folder.string() +
                    "' exists and is not a directory (or is a link)");
    std::error_code ec;
    if (!fs::is_empty(folder, ec) || ec)
        throw Error("the message folder '" + folder.string() + "' exists and is not empty");
}

}  // namespace cambium::env
