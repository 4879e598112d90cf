// SPDX-License-Identifier: Apache-2.0
// Video outputs (-o turn.mp4): frames encoded by Debian's ffmpeg, when it is installed.
#include "app/video.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <string>

#include "base/diagnostics.h"
#include "base/subprocess.h"
#include "base/output_format.h"

namespace cambium::app {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& file)
{
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

}  // namespace

namespace {

constexpr std::array<int, 3> noted_signals{SIGINT, SIGTERM, SIGHUP};
std::atomic<bool> g_noted{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "a signal handler may only store into lock-free atomics");

extern "C" void note_video_signal(int signal)
{
    g_signal.store(signal);
    g_noted.store(true);
}

}  // namespace

SignalNote::SignalNote()
{
    g_signal.store(0);
    g_noted.store(false);
    struct sigaction note {};
    note.sa_handler = note_video_signal;
    sigemptyset(&note.sa_mask);
    note.sa_flags = SA_RESETHAND | SA_RESTART;
    for (std::size_t i = 0; i < noted_signals.size(); ++i)
        ::sigaction(noted_signals[i], &note, &m_saved[i]);
}

SignalNote::~SignalNote()
{
    for (std::size_t i = 0; i < noted_signals.size(); ++i)
        ::sigaction(noted_signals[i], &m_saved[i], nullptr);
    g_signal.store(0);
}

const std::atomic<bool>* SignalNote::cancel() const { return &g_noted; }

int SignalNote::signal() { return g_signal.load(); }

bool is_video(const fs::path& file)
{
    const OutputFormat* format = find_output_format(file);
    return format && format->video;
}

fs::path require_ffmpeg(const fs::path& video)
{
    if (const char* path = std::getenv("PATH")) {
        std::string dirs = path;
        for (std::size_t start = 0; start <= dirs.size();) {
            std::size_t end = dirs.find(':', start);
            if (end == std::string::npos)
                end = dirs.size();
            fs::path candidate = fs::path(dirs.substr(start, end - start)) / "ffmpeg";
            if (end > start && ::access(candidate.c_str(), X_OK) == 0)
                return candidate;
            start = end + 1;
        }
    }
    throw Error(FileLoc{video.string()},
                "videos are encoded by ffmpeg, which is not installed: install it (Debian: "
                "apt-get install ffmpeg), or write frames with -o frame%03d.png");
}

fs::path video_frame_pattern(const PrivateFolder& folder) { return folder.path() / "%06d.png"; }

void encode_video(const fs::path& ffmpeg, const PrivateFolder& folder, int fps,
                  const fs::path& video)
{
    // Relative names inside the private folder, where ffmpeg runs: its -y can only
    // replace what this run made there.
    std::string encoded = "encoded" + video.extension().string();
    bool webm = lower_extension(video) == ".webm";
    ProcessIo io;
    io.capture = false;  // ffmpeg's messages go to the user
    ProcessResult result =
        run_process({fs::absolute(ffmpeg).string(), "-nostdin", "-hide_banner", "-loglevel",
                     "error", "-y", "-framerate", std::to_string(fps), "-pattern_type", "glob",
                     "-i", "*.png", "-c:v", webm ? "libvpx-vp9" : "libx264", "-pix_fmt", "yuv420p",
                     // yuv420p needs even dimensions
                     "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", encoded},
                    folder.path(), io, ProcessLimits{0, 0, 0, 0});
    if (result.end != ProcessResult::End::exited || result.exit_code != 0)
        throw Error(FileLoc{video.string()},
                    "ffmpeg could not encode the frames (see ffmpeg's message above)");
    folder.move_onto(encoded, video);
}

}  // namespace cambium::app
