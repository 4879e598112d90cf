// SPDX-License-Identifier: Apache-2.0
// Comparing a render with cpfg's window image: silhouettes and colours.
#include "image_compare.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "app/pipeline.h"
#include "render/color.h"
#include "render/render.h"

namespace cambium::test {
namespace {

/// Pixels apart that still count as the same place (cpfg's lines and polygon edges are
/// rasterised differently from ray-traced ones).
constexpr int tolerance_px = 2;
constexpr double min_agreement = 0.95;
/// How far (of 255) a pixel may lie from the background colour and still count as
/// background: the tolerance read_cpfg_image gives cpfg's picture.
constexpr float background_tolerance = 3;
constexpr double max_hue_difference_deg = 15;
/// Hue is compared only where enough pixels of both images have one.
constexpr std::size_t min_hue_pixels = 200;
/// Our HSV value over cpfg's, median over the plant. cpfg's window adds a flat ambient
/// term and lights with OpenGL's unnormalised Lambert term; the path tracer's light is
/// physical (directional light of radiance pi, sRGB-decoded albedo, soft ambient from
/// the environment), so shaded parts come out within about 2x of cpfg's either way.
constexpr double min_value_ratio = 0.5, max_value_ratio = 2.0;


/// The square dilation of `mask` by `radius` pixels (separable: rows, then columns).
std::vector<bool> dilate(const std::vector<bool>& mask, int width, int height, int radius)
{
    std::vector<bool> rows(mask.size()), out(mask.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            bool any = false;
            for (int d = std::max(0, x - radius); d <= std::min(width - 1, x + radius) && !any; ++d)
                any = mask[std::size_t(y) * width + d];
            rows[std::size_t(y) * width + x] = any;
        }
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            bool any = false;
            for (int d = std::max(0, y - radius); d <= std::min(height - 1, y + radius) && !any; ++d)
                any = rows[std::size_t(d) * width + x];
            out[std::size_t(y) * width + x] = any;
        }
    return out;
}

/// The fraction of `of`'s pixels inside `within`.
double fraction_inside(const std::vector<bool>& of, const std::vector<bool>& within)
{
    std::size_t n = 0, inside = 0;
    for (std::size_t i = 0; i < of.size(); ++i)
        if (of[i]) {
            ++n;
            inside += within[i];
        }
    return n == 0 ? 1.0 : double(inside) / double(n);
}

struct Hsv {
    double h = 0, s = 0, v = 0;
};

Hsv hsv(const float* c)
{
    double mx = std::max({c[0], c[1], c[2]}), mn = std::min({c[0], c[1], c[2]});
    Hsv r;
    r.v = mx;
    r.s = mx > 0 ? (mx - mn) / mx : 0;
    if (mx == mn)
        return r;
    double d = mx - mn;
    if (mx == c[0])
        r.h = 60 * std::fmod((c[1] - c[2]) / d + 6, 6.0);
    else if (mx == c[1])
        r.h = 60 * ((c[2] - c[0]) / d + 2);
    else
        r.h = 60 * ((c[0] - c[1]) / d + 4);
    return r;
}

double median(std::vector<double> v)
{
    if (v.empty())
        return 0;
    auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

}  // namespace

PlantImage read_cpfg_image(const std::string& file, const std::array<float, 3>& window_background)
{
    auto in = OIIO::ImageInput::open(file);
    if (!in)
        throw std::runtime_error("cannot read " + file);
    const OIIO::ImageSpec& spec = in->spec();
    PlantImage img;
    img.width = spec.width;
    img.height = spec.height;
    std::vector<unsigned char> bytes(std::size_t(img.width) * img.height * 3);
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, bytes.data()))
        throw std::runtime_error("cannot read " + file);
    auto colour = [&](int x, int y) {
        const unsigned char* p = &bytes[(std::size_t(y) * img.width + x) * 3];
        return (p[0] << 16) | (p[1] << 8) | p[2];
    };
    std::map<int, int> border;
    for (int x = 0; x < img.width; ++x) {
        ++border[colour(x, 0)];
        ++border[colour(x, img.height - 1)];
    }
    for (int y = 0; y < img.height; ++y) {
        ++border[colour(0, y)];
        ++border[colour(img.width - 1, y)];
    }
    int background = std::max_element(border.begin(), border.end(), [](auto& a, auto& b) {
                         return a.second < b.second;
                     })->first;
    bool window_shows_background = true;
    for (int c = 0; c < 3; ++c) {
        int bg = (background >> (16 - 8 * c)) & 0xff;
        window_shows_background = window_shows_background && std::abs(bg - window_background[c] * 255) <= 3;
    }
    img.rgb.resize(bytes.size());
    img.plant.resize(bytes.size() / 3);
    for (std::size_t i = 0; i < img.plant.size(); ++i) {
        bool differs = false;
        for (int c = 0; c < 3; ++c) {
            img.rgb[3 * i + c] = bytes[3 * i + c] / 255.0f;
            int bg = (background >> (16 - 8 * c)) & 0xff;
            differs = differs || std::abs(int(bytes[3 * i + c]) - bg) > 3;
        }
        img.plant[i] = differs || !window_shows_background;
    }
    return img;
}

ImageAgreement compare_images(const PlantImage& ours, const PlantImage& cpfg)
{
    if (ours.width != cpfg.width || ours.height != cpfg.height)
        throw std::runtime_error(fmt::format("image sizes differ: {}x{} and cpfg's {}x{}", ours.width,
                                             ours.height, cpfg.width, cpfg.height));
    ImageAgreement a;
    a.precision = fraction_inside(ours.plant, dilate(cpfg.plant, cpfg.width, cpfg.height, tolerance_px));
    a.recall = fraction_inside(cpfg.plant, dilate(ours.plant, ours.width, ours.height, tolerance_px));
    std::vector<double> hue, value;
    for (std::size_t i = 0; i < ours.plant.size(); ++i) {
        if (!ours.plant[i] || !cpfg.plant[i])
            continue;
        Hsv o = hsv(&ours.rgb[3 * i]), c = hsv(&cpfg.rgb[3 * i]);
        if (c.v > 0.02)
            value.push_back(o.v / c.v);
        if (o.s > 0.15 && c.s > 0.15 && o.v > 0.15 && c.v > 0.15) {
            double d = std::fabs(o.h - c.h);
            hue.push_back(std::min(d, 360 - d));
        }
    }
    a.hue_pixels = hue.size();
    a.median_hue_difference = median(hue);
    a.median_value_ratio = value.empty() ? 1 : median(value);
    return a;
}

PlantImage render_for_comparison(const app::Options& options)
{
    app::Model loaded = app::load_model(options);
    geom::Scene scene = app::interpret(loaded, app::derive(loaded, options), options);
    render::RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.samples_per_pixel = 2;
    settings.max_depth = 3;
    settings.threads = 2;
    settings.transparent_background = true;
    render::Image image = render::render(scene, settings);
    PlantImage out;
    out.background = {scene.background.r, scene.background.g, scene.background.b};
    const std::array<float, 3>& background = out.background;
    out.width = image.width;
    out.height = image.height;
    out.rgb.resize(std::size_t(image.width) * image.height * 3);
    out.plant.resize(std::size_t(image.width) * image.height);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            std::size_t i = std::size_t(y) * image.width + x;
            float alpha = image.at(x, y, 3);
            bool shows_background = true;
            for (int c = 0; c < 3; ++c) {  // straight colour from the premultiplied
                out.rgb[3 * i + c] = alpha > 0 ? render::linear_to_srgb(image.at(x, y, c) / alpha) : 0;
                shows_background = shows_background &&
                                   std::abs(out.rgb[3 * i + c] - background[c]) * 255 <= background_tolerance;
            }
            out.plant[i] = alpha >= 0.5f && !shows_background;
        }
    return out;
}

bool ImageAgreement::silhouettes_agree() const
{
    return precision >= min_agreement && recall >= min_agreement;
}

bool ImageAgreement::colours_agree() const
{
    return (hue_pixels < min_hue_pixels || median_hue_difference <= max_hue_difference_deg) &&
           median_value_ratio >= min_value_ratio && median_value_ratio <= max_value_ratio;
}

std::string ImageAgreement::describe() const
{
    return fmt::format("precision {:.3f} recall {:.3f} hue {:.1f} deg ({} px) value x{:.2f}", precision,
                       recall, median_hue_difference, hue_pixels, median_value_ratio);
}

}  // namespace cambium::test
