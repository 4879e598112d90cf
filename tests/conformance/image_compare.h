// SPDX-License-Identifier: Apache-2.0
// Comparing a render with cpfg's window image (the oracle's image.png) as a person would:
// where the plant is (silhouettes within a few pixels) and what colour it is.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace cambium::test {

/// An 8-bit-per-channel display image (sRGB), with which pixels show the plant.
struct PlantImage {
    int width = 0, height = 0;
    std::vector<float> rgb;    ///< display values in [0, 1], 3 per pixel
    std::vector<bool> plant;   ///< per pixel: the plant, not the background
};

/// cpfg's window image: the plant is every pixel whose colour differs from the
/// background (the most common colour of the border) by more than 3/255 in a channel.
/// When that colour is not the window's `background` (display values in [0, 1]) either,
/// geometry fills the window and hides the background: every pixel is the plant.
PlantImage read_cpfg_image(const std::string& file, const std::array<float, 3>& background);

struct ImageAgreement {
    /// Silhouettes: the fraction of our plant pixels within `tolerance_px` of cpfg's
    /// (precision) and of cpfg's within `tolerance_px` of ours (recall).
    double precision = 0, recall = 0;
    /// Over pixels both call plant, where both have a hue (saturation and value above
    /// 0.15): the median hue difference in degrees, and how many such pixels there were.
    double median_hue_difference = 0;
    std::size_t hue_pixels = 0;
    /// Over pixels both call plant: the median of our HSV value over cpfg's.
    double median_value_ratio = 1;

    std::string describe() const;
};

/// Compares `ours` with `cpfg` (the same size) pixel by pixel.
ImageAgreement compare_images(const PlantImage& ours, const PlantImage& cpfg, int tolerance_px);

}  // namespace cambium::test
