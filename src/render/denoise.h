// SPDX-License-Identifier: Apache-2.0
// Denoising a rendered frame from what the path tracer knows per pixel (docs/denoise.md):
// the Denoiser interface and Cambium's own filter behind it.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace cambium::render {

/// The organ id of a pixel (Image::organ) whose camera rays met nothing.
inline constexpr std::uint32_t organ_background = 0xffffffffu;
/// ... whose nearest camera-ray hit was the ground plane (--ground).
inline constexpr std::uint32_t organ_ground = 0xfffffffeu;
/// ... whose nearest hit was a primitive no module is known to have drawn.
inline constexpr std::uint32_t organ_unknown = 0xfffffffdu;

/// What a denoiser reads: the film's buffers over width x height pixels, rows top to
/// bottom. Every span but `beauty` may be empty (not known); the others hold
/// width x height entries of their stated size.
struct DenoiseInput {
    int width = 0, height = 0;
    std::span<const float> beauty;    ///< RGBA, 4 per pixel (A: coverage, kept as it is)
    /// The variance of each RGB channel's pixel mean, 3 per pixel: estimated from the
    /// pixel's two half sample sets (even and odd samples, independently scrambled),
    /// a quarter of the squared difference of their means.
    std::span<const float> variance;
    std::span<const float> albedo;  ///< the first hit's diffuse colour, 3 per pixel
    std::span<const float> normal;  ///< the first hit's shading normal, 3 per pixel
    std::span<const float> depth;   ///< the nearest hit's distance, 1 (infinity: none)
    /// The organ (the module that drew the nearest hit, or organ_background,
    /// organ_ground, organ_unknown), 1 per pixel: pixels of different organs are never
    /// mixed.
    std::span<const std::uint32_t> organ;
    /// The variance of the albedo's and of the normal's pixel means (2 per pixel, each
    /// summed over its channels), estimated as `variance` is: large where a pixel's
    /// samples see different surfaces (its silhouette), so that such pixels may still be
    /// averaged with their like.
    std::span<const float> feature_variance;
};

/// A denoiser of rendered frames: Cambium's own (NlMeansDenoiser) or, where one is
/// installed, a library's. Called once per frame, so the call is virtual.
class Denoiser {
public:
    virtual ~Denoiser() = default;
    /// Its name, as docs/denoise.md and --stats name it.
    virtual std::string name() const = 0;
    /// The bytes of working memory denoise() takes for a width x height frame, beyond
    /// its input and output (for the --max-memory check before rendering).
    virtual std::uint64_t working_bytes(int width, int height) const = 0;
    /// The denoised RGBA, 4 floats per pixel, alpha copied from the beauty. Must be a
    /// pure function of the input: byte-identical for any thread count (it runs in the
    /// caller's TBB arena). Throws cambium::Error on malformed input.
    virtual std::vector<float> denoise(const DenoiseInput& input) const = 0;
};

/// NlMeansDenoiser's parameters (docs/denoise.md). The defaults were chosen on the
/// benchmark plants; none depends on the image.
struct NlMeansParameters {
    int search_radius = 7;  ///< neighbours up to this many pixels away on each axis
    int patch_radius = 2;   ///< the colour distance compares (2r+1)^2 patches
    /// Colour weights: a patch distance of 1 means a difference of `colour_k` standard
    /// deviations of the two pixels' noise; `variance_cancel` of the expected squared
    /// difference (which noise alone gives) is subtracted first.
    float colour_k = 0.45f;
    float variance_cancel = 1.0f;
    /// Feature tolerances: the weight falls by e per tolerance squared of difference
    /// (beyond what the features' own noise explains, and the noise's variance added to
    /// the tolerance's square: Rousselle, Manzi & Zwicker 2013).
    float albedo_tolerance = 0.08f;  ///< albedo units (reflectance)
    float normal_tolerance = 0.35f;  ///< length of the normals' difference
    /// Depth: the neighbour's depth against the centre's plane (its depth and depth
    /// gradient), relative to the centre's depth.
    float depth_tolerance = 0.02f;
    /// The half-width of the box that smooths each pixel's variance (over pixels of its
    /// own organ): one pixel's estimate has a single degree of freedom per channel.
    int variance_radius = 2;
};

/// A cross-bilateral non-local-means filter (docs/denoise.md): each pixel becomes a
/// weighted mean of its neighbours within the search window, weighted by the similarity
/// of their colour patches measured in units of the pixels' own noise (Rousselle,
/// Knaus & Zwicker 2012) times the similarity of their features: albedo, normal, depth
/// (Rousselle, Manzi & Zwicker 2013); pixels of another organ weigh nothing.
class NlMeansDenoiser final : public Denoiser {
public:
    explicit NlMeansDenoiser(const NlMeansParameters& parameters = {});
    std::string name() const override { return "nl-means"; }
    std::uint64_t working_bytes(int width, int height) const override;
    std::vector<float> denoise(const DenoiseInput& input) const override;

    const NlMeansParameters& parameters() const { return m_parameters; }

private:
    NlMeansParameters m_parameters;
};

/// The denoiser --denoise uses.
std::unique_ptr<Denoiser> make_default_denoiser();

}  // namespace cambium::render
