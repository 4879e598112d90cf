// SPDX-License-Identifier: Apache-2.0
// The film: each sampled pixel's running sums, adaptive sampling's convergence test over
// them, and their resolution into an Image.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "geom/scene.h"
#include "render/denoise.h"
#include "render/image.h"
#include "render/organ_masks.h"
#include "render/vecf.h"

namespace cambium::render {

/// A pixel's running sums that every render keeps: small (24 bytes), because every pass
/// reads and writes them for every pixel, most of them the background's, so a tile row's
/// sums share a few cache lines (with the other sums beside them, 104 bytes a pixel,
/// reading them was most of the pixel loop's cache misses).
struct PixelState {
    Vec3f radiance;
    std::uint32_t samples = 0, hits = 0;
    bool done = false;  // adaptive sampling: converged
};

/// A pixel's sums that only some renders keep (Film::extras): the albedo, normal and depth
/// layers, adaptive sampling's luminance sums, the shadow catcher's light.
struct PixelExtras {
    Vec3f albedo, normal;
    float depth = std::numeric_limits<float>::infinity();
    /// Luminance sums of the two independent replicas (even and odd samples), for the
    /// adaptive error estimate (relative_error_squared).
    std::array<double, 2> replica_luminance{};
    double luminance_sq = 0;
    double lit_with = 0, lit_without = 0;  // shadow-catcher samples' light (PathResult)
    std::uint32_t caught = 0;              // samples that met the shadow catcher
    /// Denoising: the odd samples' radiance sum (the even ones' is the rest), and the
    /// organ of the nearest camera-ray hit (the one `depth` is of).
    Vec3f odd_radiance, odd_albedo, odd_normal;
    std::uint32_t organ = organ_background;
};

/// The sampled pixels' sums, row by row.
struct Film {
    std::vector<PixelState> px;
    /// Beside px, where the render has AOVs, adaptive sampling or a shadow catcher (the
    /// only renders whose samples add to them); else empty.
    std::vector<PixelExtras> extras;

    /// Organ masks: the organs each pixel's samples met; else empty.
    std::vector<OrganSamples> organs;

    Film(std::size_t pixels, bool with_extras, bool with_organs)
        : px(pixels), extras(with_extras ? pixels : 0), organs(with_organs ? pixels : 0)
    {
    }
    PixelExtras* extra(std::size_t i) { return extras.empty() ? nullptr : &extras[i]; }
};

/// The layers resolve makes beside RGBA, from the render's settings.
struct ImageLayers {
    bool transparent = false;  ///< Image::transparent: misses added nothing
    bool aovs = false;         ///< albedo, normal and depth (the film keeps extras)
    /// The denoiser's inputs: variance, feature variance and organ (the film's samples
    /// came from two replicas).
    bool denoise = false;
    int organ_mask_depth = 0;  ///< of the organ masks, made where the film keeps organs
};

/// Marks pixels whose 3x3 neighbourhood meets the noise target as done (over the sampled
/// rectangle, w x h: its edges are the image's or lie in the crop's margin). Needs the
/// film's extras.
void mark_converged(Film& film, int w, int h, double target);

/// The image of the sums so far over `out`, from the sums over `sampled` (which holds it);
/// `scene` names the organs of the organ masks.
Image resolve(const Film& film, const PixelRect& sampled, const PixelRect& out,
              const ImageLayers& layers, const geom::Scene& scene);

}  // namespace cambium::render
