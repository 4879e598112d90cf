// SPDX-License-Identifier: Apache-2.0
// Comparing a render with cpfg's window image (the oracle's image.png) as a person would:
// where the plant is (silhouettes within a few pixels) and what colour it is.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "app/command_line.h"

namespace cambium::test {

/// An 8-bit-per-channel display image (sRGB), with which pixels show the plant.
struct PlantImage {
    int width = 0, height = 0;
    std::vector<float> rgb;    ///< display values in [0, 1], 3 per pixel
    std::vector<bool> plant;   ///< per pixel: the plant, not the background
    std::array<float, 3> background{};  ///< the window's background colour (display values)
};

/// A model rendered at cpfg's window size for comparison (2 samples a pixel), as display
/// colours, with the plant being every pixel the plant covers at least half of, unless
/// it shows the window's background colour: cpfg's picture tells the plant by colour
/// alone (read_cpfg_image), so geometry drawn in the background colour (a black disc on
/// black) is no more part of the visible silhouette in ours than in cpfg's.
PlantImage render_for_comparison(const app::Options& options);

/// cpfg's window image: the plant is every pixel whose colour differs from the
/// background (the most common colour of the border) by more than 3/255 in a channel.
/// When that colour is not the window's `background` (display values in [0, 1]) either,
/// geometry fills the window and hides the background: every pixel is the plant.
PlantImage read_cpfg_image(const std::string& file, const std::array<float, 3>& background);

struct ImageAgreement {
    /// Silhouettes: the fraction of our plant pixels within 2 px of cpfg's
    /// (precision) and of cpfg's within 2 px of ours (recall).
    double precision = 0, recall = 0;
    /// Over pixels both call plant, where both have a hue (saturation and value above
    /// 0.15): the median hue difference in degrees, and how many such pixels there were.
    double median_hue_difference = 0;
    std::size_t hue_pixels = 0;
    /// Over pixels both call plant: the median of our HSV value over cpfg's.
    double median_value_ratio = 1;

    /// Within 2 px of each other, 95% of each silhouette's pixels.
    bool silhouettes_agree() const;
    /// Median hue within 15 degrees (where enough pixels have one) and median value
    /// within a factor 2 of cpfg's.
    bool colours_agree() const;
    std::string describe() const;
};

/// Compares `ours` with `cpfg` (the same size) pixel by pixel.
ImageAgreement compare_images(const PlantImage& ours, const PlantImage& cpfg);

}  // namespace cambium::test
