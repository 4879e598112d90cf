// SPDX-License-Identifier: Apache-2.0
// cpfg's animation file (.a, manual 5.3) and the frames it selects.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "geom/vec.h"

namespace cambium::geom {

/// Frame numbers (`first frame`, `last frame`, interval ends) and steps are derivation
/// steps: at most the derivation length's limit (lsys::max_derivation_steps). Larger
/// values are errors at their file:line:column, not billions of steps.
constexpr int max_animation_frame = 1'000'000;
/// At most this many `frame intervals:` items (more could not each select a frame).
constexpr std::size_t max_frame_intervals = 1'000'000;

/// One item of `frame intervals:`: a single frame (from == to), or a range with an
/// optional step and an optional rotation or scaling of the object after each frame.
struct FrameInterval {
    enum class Change { none, rotate, scale };
    int from = 0, to = 0;
    std::optional<int> step;  ///< absent: the file's `step:`; 0: frames without derivation
    Change change = Change::none;
    Vec3 amount{0, 0, 0};     ///< degrees about x, y, z (rotate) or factors (scale)
    FileLoc change_loc;       ///< where the rotate or scale numbers are, for errors
};

/// The commands of an animation file, with cpfg's defaults.
struct AnimationFile {
    bool double_buffer = true;             ///< accepted (a window setting)
    bool clear_between_frames = true;      ///< accepted (every frame is drawn anew)
    bool scale_between_frames = false;     ///< on: the view is refitted to every frame
    bool new_view_between_frames = false;  ///< on: the view file is reread every frame
    bool center_between_frames = false;    ///< accepted (cpfg's recentring)
    bool hcenter_between_frames = false;   ///< accepted
    int swap_interval = 1;                 ///< accepted (tenths of a second on screen)
    int first_frame = 1;
    std::optional<int> last_frame;         ///< absent or negative: the derivation length
    int step = 1;
    std::vector<FrameInterval> intervals;  ///< `frame intervals:` (wins over first/last/step)
};

/// Reads an animation file. Unknown commands are warned about and skipped (cpfg);
/// malformed values throw cambium::Error naming file, line and column.
AnimationFile read_animation_file(const std::filesystem::path& file);
/// The same from text (`name` in messages).
AnimationFile parse_animation_file(std::string_view text, std::string_view name);

/// One frame of an animation: which derivation step is shown and how.
struct AnimationFrame {
    int number = 0;       ///< the frame's number: the derivation step as cpfg counts it
    int derive_steps = 0; ///< steps to derive after the previous frame (the first: from the axiom)
    Vec3 rotation_deg{0, 0, 0};  ///< accumulated `rotate` of frame intervals (x, then y, then z)
    Vec3 scale{1, 1, 1};         ///< accumulated `scale` of frame intervals
};

/// The frames cpfg's animation mode records, in order: the first frame, then after each
/// frame the derivation advances to the next selected step until the last frame is
/// reached or passed. `derivation_length` stands for a missing or negative `last frame:`.
/// Throws cambium::Error when the animation would have more than `max_frames` frames.
std::vector<AnimationFrame> select_frames(const AnimationFile& animation, int derivation_length,
                                          int max_frames = 1'000'000);

/// cpfg's defaults without an animation file (manual 4.2): frames 1 to the derivation
/// length, step 1.
AnimationFile default_animation();

}  // namespace cambium::geom
