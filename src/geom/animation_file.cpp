// SPDX-License-Identifier: Apache-2.0
// cpfg's animation file (.a, manual 5.3) and the frames it selects.
//
// Frame selection follows cpfg's animation mode: the derivation goes to the first frame;
// after each frame it advances to the next step that `frame intervals:` selects (the
// first interval whose end lies ahead of the current step and that still holds a frame
// after it), or by `step:` when no interval does, until the last frame is reached or
// passed. So `1-500 step 2` records 1, 3, ..., 499 and then 500, the last frame.
#include "geom/animation_file.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "base/diagnostics.h"
#include "geom/text_input.h"

namespace cambium::geom {
namespace {

/// Reads the words of one value, with their columns for messages.
class LineValue {
public:
    LineValue(std::string_view text, std::size_t start, FileLoc line)
        : m_text(text), m_at(start), m_line(std::move(line))
    {
    }

    bool at_end()
    {
        skip_blanks();
        return m_at >= m_text.size();
    }
    /// The next word (letters), or "" when the next thing is not a word.
    std::string_view peek_word()
    {
        skip_blanks();
        std::size_t end = m_at;
        while (end < m_text.size() && std::isalpha(static_cast<unsigned char>(m_text[end])))
            ++end;
        return m_text.substr(m_at, end - m_at);
    }
    void skip(std::size_t n) { m_at += n; }
    bool take(char c)
    {
        skip_blanks();
        if (m_at < m_text.size() && m_text[m_at] == c) {
            ++m_at;
            return true;
        }
        return false;
    }
    int integer(const char* what) { return number<int>(what); }
    /// A whole number from `low` to max_animation_frame (a frame number or a step).
    int bounded(const char* what, int low)
    {
        std::size_t at = m_at;
        int n = integer(what);
        if (n < low || n > max_animation_frame) {
            m_at = at;
            skip_blanks();
            fail(std::string(what) + " must be from " + std::to_string(low) + " to " +
                 std::to_string(max_animation_frame) + " (the derivation length's limit), not " +
                 std::to_string(n));
        }
        return n;
    }
    /// A finite number within single precision, cpfg's type for the frame intervals' values.
    double real()
    {
        skip_blanks();
        std::size_t at = m_at;
        double value = number<double>("a number");
        if (!std::isfinite(value) || std::abs(value) > std::numeric_limits<float>::max()) {
            std::size_t end = at;
            while (end < m_text.size() && !std::isspace(static_cast<unsigned char>(m_text[end])) &&
                   m_text[end] != ',')
                ++end;
            m_at = at;
            fail("expected a number, found '" + std::string(m_text.substr(at, end - at)) + "'");
        }
        return value;
    }
    FileLoc here()
    {
        skip_blanks();
        FileLoc at = m_line;
        at.column = static_cast<int>(m_at) + 1;
        return at;
    }
    [[noreturn]] void fail(const std::string& message) const
    {
        FileLoc at = m_line;
        at.column = static_cast<int>(m_at) + 1;
        throw Error(at, message);
    }

private:
    void skip_blanks()
    {
        while (m_at < m_text.size() && (m_text[m_at] == ' ' || m_text[m_at] == '\t' ||
                                        m_text[m_at] == '\r'))
            ++m_at;
    }
    template <typename T>
    T number(const char* what)
    {
        skip_blanks();
        T value{};
        const char* begin = m_text.data() + m_at;
        const char* end = m_text.data() + m_text.size();
        if (begin < end && *begin == '+')
            ++begin;
        auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec != std::errc() || ptr == begin)
            fail(std::string("expected ") + what);
        m_at = static_cast<std::size_t>(ptr - m_text.data());
        return value;
    }

    std::string_view m_text;
    std::size_t m_at;
    FileLoc m_line;
};

bool read_flag(LineValue& value)
{
    std::string_view word = value.peek_word();
    if (word != "on" && word != "off")
        value.fail("expected on or off");
    value.skip(word.size());
    return word == "on";
}

/// One item of `frame intervals:` up to its comma.
FrameInterval read_interval(LineValue& value)
{
    FrameInterval interval;
    interval.from = value.bounded("a frame number", 0);
    interval.to = interval.from;
    if (value.take('-'))
        interval.to = value.bounded("the last frame of the range", 0);
    if (interval.from < 0 || interval.to < interval.from)
        value.fail("a frame range goes from a frame to a later one");
    for (std::string_view word = value.peek_word(); !word.empty(); word = value.peek_word()) {
        value.skip(word.size());
        if (word == "step" && !interval.step) {
            interval.step = value.bounded("the step of the range", 0);
        } else if ((word == "rotate" || word == "scale") &&
                   interval.change == FrameInterval::Change::none) {
            interval.change = word == "rotate" ? FrameInterval::Change::rotate
                                               : FrameInterval::Change::scale;
            interval.change_loc = value.here();
            interval.amount.x = value.real();
            interval.amount.y = value.real();
            interval.amount.z = value.real();
        } else {
            value.fail("expected step, rotate or scale (one each) after a frame range, not '" +
                       std::string(word) + "'");
        }
    }
    return interval;
}

std::string trimmed(std::string_view s)
{
    std::size_t b = s.find_first_not_of(" \t\r");
    std::size_t e = s.find_last_not_of(" \t\r");
    return b == std::string_view::npos ? std::string() : std::string(s.substr(b, e - b + 1));
}

}  // namespace

AnimationFile default_animation() { return AnimationFile{}; }

AnimationFile parse_animation_file(std::string_view text, std::string_view name)
{
    AnimationFile a;
    int line_number = 0;
    for (std::size_t start = 0; start < text.size();) {
        std::size_t end = text.find('\n', start);
        if (end == std::string_view::npos)
            end = text.size();
        std::string_view line = text.substr(start, end - start);
        start = end + 1;
        ++line_number;
        FileLoc loc{std::string(name), line_number, 1};
        if (trimmed(line).empty())
            continue;
        std::size_t colon = line.find(':');
        if (colon == std::string_view::npos) {
            warn(loc, "not an animation command (no ':'); line ignored");
            continue;
        }
        std::string command = trimmed(line.substr(0, colon));
        LineValue value(line, colon + 1, loc);
        if (command == "double buffer")
            a.double_buffer = read_flag(value);
        else if (command == "clear between frames")
            a.clear_between_frames = read_flag(value);
        else if (command == "scale between frames")
            a.scale_between_frames = read_flag(value);
        else if (command == "new view between frames")
            a.new_view_between_frames = read_flag(value);
        else if (command == "center between frames")
            a.center_between_frames = read_flag(value);
        else if (command == "hcenter between frames")
            a.hcenter_between_frames = read_flag(value);
        else if (command == "swap interval")
            a.swap_interval = value.integer("a whole number");
        else if (command == "first frame")
            a.first_frame = std::max(
                0, value.bounded("a frame number", -max_animation_frame));  // cpfg clamps to 0
        else if (command == "last frame")
            a.last_frame = value.bounded("a frame number",
                                         -max_animation_frame);  // negative: the derivation length
        else if (command == "step")
            a.step = std::max(
                1, value.bounded("the step", -max_animation_frame));  // cpfg: 0 or less is 1
        else if (command == "frame intervals") {
            a.intervals.clear();
            do {
                if (a.intervals.size() == max_frame_intervals)
                    value.fail("more than " + std::to_string(max_frame_intervals) +
                               " frame intervals");
                a.intervals.push_back(read_interval(value));
            } while (value.take(','));
        } else if (command == "display on request" || command == "frame numbers") {
            value.peek_word();  // later cpfg versions' interactive settings: nothing to do
            continue;
        } else {
            warn(loc, "unknown animation command '" + command + "'; line ignored");
            continue;
        }
        if (!value.at_end())
            value.fail("unexpected text after the value of '" + command + "'");
    }
    if (!a.intervals.empty()) {
        // frame intervals win over first frame, last frame (manual 5.3)
        a.first_frame = a.intervals.front().from;
        a.last_frame = a.intervals.back().to;
    }
    return a;
}

AnimationFile read_animation_file(const std::filesystem::path& file)
{
    return parse_animation_file(read_text_file(file, "animation file"), file.string());
}

namespace {

/// Steps from `frame` to the next selected frame, as cpfg decides it after each frame;
/// applies the interval's rotation or scaling to `next`. A range with step 0 shows the
/// next frame number without deriving. Intervals before `first_live` hold no frame
/// after the current one; as frame numbers only grow, an interval found so stays so,
/// and skipping them keeps the selection linear in intervals plus frames.
void advance_to_next_frame(const AnimationFile& a, AnimationFrame& next, std::size_t& first_live)
{
    int current = next.number;
    for (std::size_t i = first_live; i < a.intervals.size(); ++i) {
        const FrameInterval& interval = a.intervals[i];
        // every interval from first_live to i is dead: the scan stops at the first live one
        first_live = i + 1;
        if (current >= interval.to)
            continue;
        int step = interval.step ? std::max(*interval.step, 1) : a.step;
        int n = interval.from;
        if (n <= current)
            n += ((current - n) / step + 1) * step;
        if (n > interval.to)
            continue;
        first_live = i;
        if (interval.change == FrameInterval::Change::rotate)
            next.rotation_deg += interval.amount;
        else if (interval.change == FrameInterval::Change::scale)
            next.scale = {next.scale.x * interval.amount.x, next.scale.y * interval.amount.y,
                          next.scale.z * interval.amount.z};
        // a sum or product past single precision leaves the camera no finite direction
        auto beyond = [](const Vec3& v) {
            const double most = std::numeric_limits<float>::max();
            return !(std::abs(v.x) <= most && std::abs(v.y) <= most && std::abs(v.z) <= most);
        };
        if (beyond(next.rotation_deg) || beyond(next.scale))
            throw Error(interval.change_loc,
                        std::string("the accumulated ") +
                            (interval.change == FrameInterval::Change::rotate ? "rotation" : "scale") +
                            " exceeds single precision by frame " + std::to_string(n));
        if (interval.step && *interval.step == 0) {
            next.number = current + 1;
            next.derive_steps = 0;
        } else {
            next.number = n;
            next.derive_steps = n - current;
        }
        return;
    }
    next.number = current + a.step;
    next.derive_steps = a.step;
}

}  // namespace

std::vector<AnimationFrame> select_frames(const AnimationFile& a, int derivation_length,
                                          int max_frames)
{
    int last = a.last_frame && *a.last_frame >= 0 ? *a.last_frame : derivation_length;
    last = std::max(last, a.first_frame);  // cpfg: a last frame before the first is the first
    std::vector<AnimationFrame> frames;
    AnimationFrame frame;
    frame.number = a.first_frame;
    frame.derive_steps = a.first_frame;
    frames.push_back(frame);
    std::size_t first_live = 0;
    while (frame.number < last) {
        if (static_cast<int>(frames.size()) >= max_frames)
            throw Error("the animation selects more than " + std::to_string(max_frames) +
                        " frames (first frame " + std::to_string(a.first_frame) +
                        ", last frame " + std::to_string(last) + ")");
        advance_to_next_frame(a, frame, first_live);
        frames.push_back(frame);
    }
    return frames;
}

}  // namespace cambium::geom
