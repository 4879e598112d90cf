// SPDX-License-Identifier: Apache-2.0
// `@L` labels: FreeType glyphs composited at the projected anchor, depth-tested per pixel
// against the first surface along each pixel's ray (traced once per pixel for all labels).
#include "render/labels.h"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <cmath>
#include <memory>
#include <string>

#include "base/diagnostics.h"
#include "base/limits.h"
#include "render/color.h"

namespace cambium::render {
namespace {

/// The font file fontconfig matches to `font` (its best match: cpfg's X font names
/// such as courier or helvetica become whatever the system aliases them to).
std::string font_file(const geom::LabelFont& font)
{
    std::unique_ptr<FcConfig, decltype(&FcConfigDestroy)> config(FcInitLoadConfigAndFonts(), FcConfigDestroy);
    if (!config)
        throw Error("labels: fontconfig could not load its configuration");
    std::unique_ptr<FcPattern, decltype(&FcPatternDestroy)> pattern(FcPatternCreate(), FcPatternDestroy);
    FcPatternAddString(pattern.get(), FC_FAMILY, reinterpret_cast<const FcChar8*>(font.family.c_str()));
    FcPatternAddDouble(pattern.get(), FC_PIXEL_SIZE, font.pixel_size);
    FcPatternAddInteger(pattern.get(), FC_WEIGHT, font.bold ? FC_WEIGHT_BOLD : FC_WEIGHT_REGULAR);
    FcPatternAddInteger(pattern.get(), FC_SLANT, font.italic ? FC_SLANT_ITALIC : FC_SLANT_ROMAN);
    FcConfigSubstitute(config.get(), pattern.get(), FcMatchPattern);
    FcDefaultSubstitute(pattern.get());
    FcResult result = FcResultNoMatch;
    std::unique_ptr<FcPattern, decltype(&FcPatternDestroy)> match(
        FcFontMatch(config.get(), pattern.get(), &result), FcPatternDestroy);
    FcChar8* file = nullptr;
    if (!match || FcPatternGetString(match.get(), FC_FILE, 0, &file) != FcResultMatch || !file)
        throw Error("labels: no font found for '" + font.family +
                    "' (fontconfig knows no fonts; install fonts-dejavu-core)");
    return reinterpret_cast<const char*>(file);
}

/// One FreeType face at the label size, freed with its library.
class Face {
public:
    Face(const std::string& file, int pixel_size)
    {
        if (FT_Init_FreeType(&m_library) != 0)
            throw Error("labels: FreeType could not start");
        if (FT_New_Face(m_library, file.c_str(), 0, &m_face) != 0) {
            FT_Done_FreeType(m_library);
            throw Error(file + ": labels: FreeType cannot read this font");
        }
        FT_Set_Pixel_Sizes(m_face, 0, static_cast<FT_UInt>(pixel_size));
    }
    ~Face()
    {
        FT_Done_Face(m_face);
        FT_Done_FreeType(m_library);
    }
    Face(const Face&) = delete;
    Face& operator=(const Face&) = delete;

    /// The glyph of a character rendered to 8-bit coverage, or null when the font has none.
    FT_GlyphSlot glyph(unsigned char c) const
    {
        if (FT_Load_Char(m_face, c, FT_LOAD_RENDER) != 0)
            return nullptr;
        return m_face->glyph;
    }

private:
    FT_Library m_library = nullptr;
    FT_Face m_face = nullptr;
};

/// A character's glyph as drawn: its coverage (rows x width bytes, 0..255), where it
/// lies from the pen, and how far it moves the pen.
struct Glyph {
    bool present = false;  ///< false: the font has no glyph for the character
    long left = 0, top = 0, advance = 0;
    unsigned width = 0, rows = 0;
    std::vector<std::uint8_t> coverage;
};

/// The glyphs of the label font, each rendered once for all labels (at most 256: a label
/// is bytes), their storage counted against the memory budget before it is allocated.
class GlyphCache {
public:
    GlyphCache(const Face& face, const geom::LabelFont& font, const LabelLimits& limits,
               std::uint64_t& bytes)
        : m_face(face), m_font(font), m_limits(limits), m_bytes(bytes)
    {
    }

    const Glyph& operator[](unsigned char c)
    {
        Glyph& glyph = m_glyphs[c];
        if (m_loaded[c])
            return glyph;
        m_loaded[c] = true;
        FT_GlyphSlot g = m_face.glyph(c);
        if (!g)
            return glyph;
        const FT_Bitmap& b = g->bitmap;
        std::uint64_t size = std::uint64_t(b.rows) * b.width;
        m_bytes += size;
        if (m_bytes > m_limits.max_memory_bytes)
            throw Error("labels: the glyphs of the label font (" + m_font.family + ", " +
                        std::to_string(m_font.pixel_size) + " pixels) and the hidden-pixel " +
                        "depths need " + byte_size_text(m_bytes) +
                        ", more than the memory budget of " +
                        byte_size_text(m_limits.max_memory_bytes) + " (--max-memory)");
        glyph.present = true;
        glyph.left = g->bitmap_left;
        glyph.top = g->bitmap_top;
        glyph.advance = g->advance.x >> 6;
        glyph.width = b.width;
        glyph.rows = b.rows;
        glyph.coverage.resize(size);
        for (unsigned row = 0; row < b.rows; ++row)
            std::copy_n(b.buffer + std::ptrdiff_t(row) * std::abs(b.pitch), b.width,
                        glyph.coverage.begin() + std::ptrdiff_t(row) * b.width);
        return glyph;
    }

private:
    const Face& m_face;
    const geom::LabelFont& m_font;
    const LabelLimits& m_limits;
    std::uint64_t& m_bytes;
    std::array<Glyph, 256> m_glyphs{};
    std::array<bool, 256> m_loaded{};
};

/// What the scene shows through each pixel of the image: the distance to the first
/// surface along the ray through the pixel's centre, traced the first time a label
/// covers the pixel. Every label then tests its pixels against it, so labels cost at
/// most one ray per pixel of the image however many there are and however they overlap
/// (cpfg's depth test reads its depth buffer the same way).
class PixelDepths {
public:
    PixelDepths(const Camera& camera, const EmbreeScene& accel, int width, int height)
        : m_camera(camera), m_accel(accel), m_width(width),
          m_first_hit(std::size_t(width) * std::size_t(height), untraced)
    {
    }

    static std::uint64_t bytes(int width, int height)
    {
        return std::uint64_t(width) * std::uint64_t(height) * sizeof(float);
    }

    /// Whether the scene hides the point at depth `depth` (along forward) seen through
    /// the centre of picture pixel (x, y), which is image pixel (ix, iy).
    bool hidden(long x, long y, long ix, long iy, double depth)
    {
        CameraRay ray = m_camera.generate_ray(double(x) + 0.5, double(y) + 0.5);
        double along = geom::dot(ray.dir, m_camera.forward());
        if (along <= 0)
            return true;
        double t = (depth - geom::dot(ray.org - m_camera.origin(), m_camera.forward())) / along;
        if (!(t > ray.tnear))
            return false;
        float& first = m_first_hit[std::size_t(iy) * std::size_t(m_width) + std::size_t(ix)];
        if (first == untraced) {
            auto f = [](const geom::Vec3& v) { return Vec3f(float(v.x), float(v.y), float(v.z)); };
            std::optional<SurfaceHit> hit =
                m_accel.intersect(f(ray.org), f(ray.dir), float(ray.tnear),
                                  std::numeric_limits<float>::infinity());
            first = hit ? hit->t : std::numeric_limits<float>::infinity();
        }
        // blocked within [tnear, t (1 - 1e-4)], the range an occlusion ray would test
        return first <= float(t * (1 - 1e-4));
    }

private:
    static constexpr float untraced = -1;
    const Camera& m_camera;
    const EmbreeScene& m_accel;
    int m_width;
    std::vector<float> m_first_hit;
};

/// One label to draw: its text from the pen at (x, baseline), its colour and depth.
struct PlacedLabel {
    const std::string* text;
    long x, baseline;
    Vec3f colour;
    double depth;
};

/// The coverage pixels `text` lays out from the pen at x, as draw_text walks them: the
/// work compositing it costs.
std::uint64_t text_pixels(GlyphCache& glyphs, const LabelCanvas& canvas, const std::string& text,
                          long x)
{
    std::uint64_t pixels = 0;
    long pen = x;
    for (char ch : text) {
        const Glyph& g = glyphs[static_cast<unsigned char>(ch)];
        if (!g.present)
            continue;
        pixels += std::uint64_t(g.width) * g.rows;
        pen += g.advance;
        if (pen > canvas.width)
            break;
    }
    return pixels;
}

/// Lays `label` out and composites each covered pixel that the scene does not hide.
void draw_text(Image& image, const LabelCanvas& canvas, GlyphCache& glyphs, PixelDepths& depths,
               const PlacedLabel& label)
{
    long pen = label.x;
    const float rgb[3] = {label.colour.x, label.colour.y, label.colour.z};
    for (char ch : *label.text) {
        const Glyph& g = glyphs[static_cast<unsigned char>(ch)];
        if (!g.present)
            continue;
        for (unsigned row = 0; row < g.rows; ++row) {
            for (unsigned column = 0; column < g.width; ++column) {
                float a = g.coverage[std::size_t(row) * g.width + column] / 255.0f;
                long px = pen + g.left + static_cast<long>(column);
                long py = label.baseline - g.top + static_cast<long>(row);
                long ix = px - canvas.x, iy = py - canvas.y;  // in the (cropped) image
                if (a <= 0 || ix < 0 || iy < 0 || ix >= image.width || iy >= image.height)
                    continue;
                if (depths.hidden(px, py, ix, iy, label.depth))
                    continue;
                for (int c = 0; c < 3; ++c)
                    image.at(int(ix), int(iy), c) = image.at(int(ix), int(iy), c) * (1 - a) + rgb[c] * a;
                image.at(int(ix), int(iy), 3) = image.at(int(ix), int(iy), 3) * (1 - a) + a;
            }
        }
        pen += g.advance;
        if (pen > canvas.width)
            break;
    }
}

}  // namespace

void draw_labels(Image& image, const geom::Scene& scene, const Camera& camera, const EmbreeScene& accel,
                 std::optional<LabelCanvas> canvas, const LabelLimits& limits)
{
    const LabelCanvas whole = canvas.value_or(LabelCanvas{0, 0, image.width, image.height});
    bool any = std::any_of(scene.labels.begin(), scene.labels.end(),
                           [](const geom::Label& l) { return !l.text.empty(); });
    if (!any)
        return;
    Face face(font_file(scene.label_font), scene.label_font.pixel_size);
    std::uint64_t bytes = PixelDepths::bytes(image.width, image.height);
    GlyphCache glyphs(face, scene.label_font, limits, bytes);
    // Where each label goes, and the pixels all of them cover, before anything is drawn.
    std::vector<PlacedLabel> placed;
    std::uint64_t pixels = 0;
    for (const geom::Label& label : scene.labels) {
        if (label.text.empty())
            continue;
        double depth = geom::dot(label.position - camera.origin(), camera.forward());
        if (camera.projection() == Camera::Projection::perspective && depth <= 0)
            continue;  // behind the eye
        if (depth < camera.clip_near() || depth > camera.clip_far())
            continue;
        PixelPoint p = camera.project(label.position);
        if (!(p.x >= 0 && p.y >= 0 && p.x < whole.width && p.y < whole.height))
            continue;  // an invalid raster position draws nothing
        geom::Rgb colour = label.material < scene.materials.size() ? scene.materials[label.material].diffuse
                                                                   : geom::Rgb{1, 1, 1};
        PlacedLabel l{&label.text, std::lround(p.x), std::lround(p.y), decode_display(colour), depth};
        pixels += text_pixels(glyphs, whole, label.text, l.x);
        if (pixels > limits.max_glyph_pixels)
            throw Error("labels: the @L labels (" + std::to_string(scene.labels.size()) +
                        ") cover more than " + std::to_string(limits.max_glyph_pixels) +
                        " glyph pixels in all, the most labels may draw: use fewer or shorter "
                        "labels or a smaller font");
        placed.push_back(l);
    }
    if (placed.empty())
        return;
    if (bytes > limits.max_memory_bytes)
        throw Error("labels: their depth test needs " + byte_size_text(bytes) +
                    ", more than the memory budget of " + byte_size_text(limits.max_memory_bytes) +
                    " (--max-memory)");
    PixelDepths depths(camera, accel, image.width, image.height);
    for (const PlacedLabel& label : placed)
        draw_text(image, whole, glyphs, depths, label);
}

}  // namespace cambium::render
