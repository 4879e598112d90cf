// SPDX-License-Identifier: Apache-2.0
// Video outputs (-o turn.mp4): frames encoded by Debian's ffmpeg, when it is installed.
#pragma once

#include <filesystem>

namespace cambium::app {

/// Whether `file` names a video (.mp4, .mov, .mkv, .webm) rather than an image.
bool is_video(const std::filesystem::path& file);

/// ffmpeg's path on $PATH; throws cambium::Error saying how to install it when absent.
std::filesystem::path require_ffmpeg(const std::filesystem::path& video);

/// The folder a video's frames are rendered into first (kept until the encoding has
/// succeeded, so --resume can continue an interrupted sequence).
std::filesystem::path video_frames_folder(const std::filesystem::path& video);

/// Encodes the PNG frames of `folder`, in the order of their names, into `video` at
/// `fps` frames per second (H.264 or VP9 by extension, yuv420p) by running ffmpeg
/// directly (fork and exec with fixed arguments, no shell); writes a temporary file
/// and renames it, then removes the folder. Throws cambium::Error when ffmpeg fails.
void encode_video(const std::filesystem::path& ffmpeg, const std::filesystem::path& folder,
                  int fps, const std::filesystem::path& video);

}  // namespace cambium::app
