// SPDX-License-Identifier: Apache-2.0
#include "render/vector_writer.h"

#include <cairo-pdf.h>
#include <cairo-ps.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <memory>
#include <string>

#include "base/atomic_file.h"
#include "base/diagnostics.h"

namespace cambium::render {
namespace {

struct SurfaceDeleter {
    void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
    void operator()(cairo_t* c) const { cairo_destroy(c); }
};

cairo_surface_t* make_surface(VectorFormat format, const std::string& path, double w, double h)
{
    switch (format) {
    case VectorFormat::ps: {
        cairo_surface_t* s = cairo_ps_surface_create(path.c_str(), w, h);
        // Level 2 reaches every PostScript printer and viewer; cpfg wrote plain paths too
        cairo_ps_surface_restrict_to_level(s, CAIRO_PS_LEVEL_2);
        return s;
    }
    case VectorFormat::svg: return cairo_svg_surface_create(path.c_str(), w, h);
    case VectorFormat::pdf: {
        cairo_surface_t* s = cairo_pdf_surface_create(path.c_str(), w, h);
        // PDF 1.4 keeps the page objects readable, without object streams
        cairo_pdf_surface_restrict_to_version(s, CAIRO_PDF_VERSION_1_4);
        return s;
    }
    case VectorFormat::none: break;
    }
    return nullptr;
}

void draw(cairo_t* cr, const VectorDrawing& d)
{
    cairo_set_source_rgb(cr, d.background.r, d.background.g, d.background.b);
    cairo_paint(cr);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (const VectorShape& s : d.shapes) {
        cairo_set_source_rgb(cr, s.colour.r, s.colour.g, s.colour.b);
        cairo_move_to(cr, s.points[0].x, s.points[0].y);
        cairo_line_to(cr, s.points[1].x, s.points[1].y);
        if (s.kind == VectorShape::Kind::line) {
            cairo_set_line_width(cr, s.line_width);
            cairo_stroke(cr);
        } else {
            cairo_line_to(cr, s.points[2].x, s.points[2].y);
            cairo_close_path(cr);
            cairo_fill(cr);
        }
    }
}

}  // namespace

void write_vector(const VectorDrawing& drawing, const std::filesystem::path& file,
                  VectorFormat format)
{
    if (format == VectorFormat::none)
        throw Error(file.string() + ": not a vector drawing format");
    if (drawing.width <= 0 || drawing.height <= 0)
        throw Error(file.string() + ": the window has no area");
    write_file_atomically(file, [&](const std::filesystem::path& temporary) {
        std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
            make_surface(format, temporary.string(), drawing.width, drawing.height));
        std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
        draw(cr.get(), drawing);
        cairo_show_page(cr.get());
        cairo_status_t status = cairo_status(cr.get());
        cr.reset();
        cairo_surface_finish(surface.get());
        if (status == CAIRO_STATUS_SUCCESS)
            status = cairo_surface_status(surface.get());
        if (status != CAIRO_STATUS_SUCCESS)
            throw Error(file.string() + ": cannot write: " + cairo_status_to_string(status));
    });
}

}  // namespace cambium::render
