// SPDX-License-Identifier: Apache-2.0
// `@L` labels: FreeType glyphs composited at the projected anchor, depth-tested per pixel.
#include "render/labels.h"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "base/diagnostics.h"
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

/// Whether the scene hides the point at depth `depth` (along forward) seen through the
/// centre of pixel (x, y).
bool hidden(const Camera& camera, const EmbreeScene& accel, int x, int y, double depth)
{
    CameraRay ray = camera.generate_ray(x + 0.5, y + 0.5);
    double along = geom::dot(ray.dir, camera.forward());
    if (along <= 0)
        return true;
    double t = (depth - geom::dot(ray.org - camera.origin(), camera.forward())) / along;
    if (!(t > ray.tnear))
        return false;
    auto f = [](const geom::Vec3& v) { return Vec3f(float(v.x), float(v.y), float(v.z)); };
    return accel.occluded(f(ray.org), f(ray.dir), float(ray.tnear), float(t * (1 - 1e-4)));
}

/// Lays `text` out from the pen at (x, baseline) and composites each covered pixel.
void draw_text(Image& image, const LabelCanvas& canvas, const Face& face, const std::string& text,
               double x, double baseline, const Vec3f& colour, const Camera& camera,
               const EmbreeScene& accel, double depth)
{
    long pen = std::lround(x);
    long base = std::lround(baseline);
    for (char ch : text) {
        FT_GlyphSlot g = face.glyph(static_cast<unsigned char>(ch));
        if (!g)
            continue;
        const FT_Bitmap& b = g->bitmap;
        for (unsigned row = 0; row < b.rows; ++row) {
            for (unsigned column = 0; column < b.width; ++column) {
                float a = b.buffer[row * static_cast<unsigned>(std::abs(b.pitch)) + column] / 255.0f;
                long px = pen + g->bitmap_left + static_cast<long>(column);
                long py = base - g->bitmap_top + static_cast<long>(row);
                long ix = px - canvas.x, iy = py - canvas.y;  // in the (cropped) image
                if (a <= 0 || ix < 0 || iy < 0 || ix >= image.width || iy >= image.height)
                    continue;
                if (hidden(camera, accel, static_cast<int>(px), static_cast<int>(py), depth))
                    continue;
                const float rgb[3] = {colour.x, colour.y, colour.z};
                for (int c = 0; c < 3; ++c)
                    image.at(int(ix), int(iy), c) = image.at(int(ix), int(iy), c) * (1 - a) + rgb[c] * a;
                image.at(int(ix), int(iy), 3) = image.at(int(ix), int(iy), 3) * (1 - a) + a;
            }
        }
        pen += g->advance.x >> 6;
        if (pen > canvas.width)
            break;
    }
}

}  // namespace

void draw_labels(Image& image, const geom::Scene& scene, const Camera& camera, const EmbreeScene& accel,
                 std::optional<LabelCanvas> canvas)
{
    const LabelCanvas whole = canvas.value_or(LabelCanvas{0, 0, image.width, image.height});
    bool any = std::any_of(scene.labels.begin(), scene.labels.end(),
                           [](const geom::Label& l) { return !l.text.empty(); });
    if (!any)
        return;
    Face face(font_file(scene.label_font), scene.label_font.pixel_size);
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
        draw_text(image, whole, face, label.text, p.x, p.y, decode_display(colour), camera, accel,
                  depth);
    }
}

}  // namespace cambium::render
