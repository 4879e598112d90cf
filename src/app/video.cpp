// SPDX-License-Identifier: Apache-2.0
// Video outputs (-o turn.mp4): frames encoded by Debian's ffmpeg, when it is installed.
#include "app/video.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cctype>
#include <cstdlib>
#include <string>
#include <vector>

#include "base/diagnostics.h"

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

bool is_video(const fs::path& file)
{
    std::string ext = lower_extension(file);
    return ext == ".mp4" || ext == ".mov" || ext == ".mkv" || ext == ".webm";
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

fs::path video_frames_folder(const fs::path& video)
{
    fs::path folder = video;
    folder += ".frames";
    return folder;
}

void encode_video(const fs::path& ffmpeg, const fs::path& folder, int fps, const fs::path& video)
{
    fs::path temporary = video;
    temporary += ".cambium-tmp" + video.extension().string();
    bool webm = lower_extension(video) == ".webm";
    std::vector<std::string> args = {
        ffmpeg.string(), "-hide_banner", "-loglevel", "error", "-y",
        "-framerate", std::to_string(fps),
        "-pattern_type", "glob", "-i", (folder / "*.png").string(),
        "-c:v", webm ? "libvpx-vp9" : "libx264", "-pix_fmt", "yuv420p",
        // yuv420p needs even dimensions
        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
        temporary.string()};
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);

    pid_t child = ::fork();
    if (child < 0)
        throw Error(FileLoc{video.string()}, "cannot start ffmpeg");
    if (child == 0) {
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::error_code ignored;
        fs::remove(temporary, ignored);
        throw Error(FileLoc{video.string()},
                    "ffmpeg could not encode the frames in " + folder.string() +
                        " (they are kept; see ffmpeg's message above)");
    }
    std::error_code ec;
    fs::rename(temporary, video, ec);
    if (ec)
        throw Error(FileLoc{video.string()}, "cannot be written: " + ec.message());
    fs::remove_all(folder, ec);
}

}  // namespace cambium::app
