// SPDX-License-Identifier: Apache-2.0
// Video outputs (-o turn.mp4): frames encoded by Debian's ffmpeg, when it is installed.
#pragma once

#include <signal.h>

#include <array>
#include <atomic>
#include <filesystem>

#include "base/atomic_file.h"

namespace cambium::app {

/// While alive (a video is being made), SIGINT, SIGTERM and SIGHUP no longer end the
/// process where it stands: the handler only notes the signal (stores into atomics, which
/// is async-signal-safe), the renders stop at their next pass (cancel() as
/// RenderSettings::cancel) and the caller leaves by its normal path, so that the video's
/// private folders are removed by their destructors, then ends with 128 + signal() (an
/// animation stops deriving at its next frame). Each
/// handler is installed with SA_RESETHAND: a second signal acts as it would have. The
/// handlers found are put back on destruction. One at a time.
class SignalNote {
public:
    SignalNote();
    ~SignalNote();
    SignalNote(const SignalNote&) = delete;
    SignalNote& operator=(const SignalNote&) = delete;

    /// True once a signal is noted.
    const std::atomic<bool>* cancel() const;
    /// The signal a SignalNote alive noted (the last one), 0 while none is (or none lives).
    static int signal();

private:
    std::array<struct sigaction, 3> m_saved{};
};

/// Whether `file` names a video (.mp4, .mov, .mkv, .webm) rather than an image.
bool is_video(const std::filesystem::path& file);

/// ffmpeg's path on $PATH; throws cambium::Error saying how to install it when absent.
std::filesystem::path require_ffmpeg(const std::filesystem::path& video);

/// The frames' file pattern inside a video's private folder (PrivateFolder beside the
/// video: only frames this run renders are there, so only they are encoded).
std::filesystem::path video_frame_pattern(const PrivateFolder& folder);

/// Encodes the PNG frames of `folder`, in the order of their names, into `video` at
/// `fps` frames per second (H.264 or VP9 by extension, yuv420p) by running ffmpeg
/// directly (no shell, standard input /dev/null, in `folder`); ffmpeg writes inside the
/// folder and the result is renamed over `video`. Throws cambium::Error when ffmpeg
/// fails, Interrupted on Ctrl-C (ffmpeg is stopped first).
void encode_video(const std::filesystem::path& ffmpeg, const PrivateFolder& folder, int fps,
                  const std::filesystem::path& video);

}  // namespace cambium::app
