// SPDX-License-Identifier: Apache-2.0
#include "render/vector_writer.h"

#include <cairo-pdf.h>
#include <cairo-ps.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
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

/// The files' creation date: $SOURCE_DATE_EPOCH (seconds since 1970, the reproducible-builds
/// convention) when it holds one, else the epoch itself, so one command gives one file.
std::tm creation_date()
{
    std::time_t seconds = 0;
    if (const char* epoch = std::getenv("SOURCE_DATE_EPOCH")) {
        char* end = nullptr;
        errno = 0;
        const long long value = std::strtoll(epoch, &end, 10);
        if (end != epoch && *end == '\0' && errno == 0 && value >= 0 && value < 253402300800)
            seconds = static_cast<std::time_t>(value);  // up to the year 9999
    }
    std::tm date{};
    gmtime_r(&seconds, &date);
    return date;
}

/// A PostScript stream for cairo: the bytes go to `out` as they come, but the comment
/// header's `%%CreationDate:` line (the time of writing, cairo 1.16 has no setting for
/// it) becomes `date`.
class PostScriptStream {
public:
    PostScriptStream(const std::filesystem::path& path, std::string date)
        : m_out(path, std::ios::binary), m_date(std::move(date))
    {
    }
    bool good() const { return static_cast<bool>(m_out); }

    static cairo_status_t write(void* closure, const unsigned char* data, unsigned int length)
    {
        auto* self = static_cast<PostScriptStream*>(closure);
        self->take(reinterpret_cast<const char*>(data), length);
        return self->m_out ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
    }

    /// Writes what is held (a header without an end); false on a write error.
    bool finish()
    {
        m_out << m_line;
        m_line.clear();
        m_out.flush();
        return static_cast<bool>(m_out);
    }

private:
    void take(const char* data, std::size_t length)
    {
        if (m_header_done) {
            m_out.write(data, static_cast<std::streamsize>(length));
            return;
        }
        // the header's lines are seen whole: cairo writes them in pieces
        for (std::size_t i = 0; i < length && !m_header_done; ++i) {
            m_line += data[i];
            if (data[i] != '\n')
                continue;
            if (m_line.rfind("%%CreationDate:", 0) == 0)
                m_line = "%%CreationDate: " + m_date + "\n";
            m_header_done = m_line.rfind("%%EndComments", 0) == 0;
            m_out << m_line;
            m_line.clear();
            if (m_header_done)
                m_out.write(data + i + 1, static_cast<std::streamsize>(length - i - 1));
        }
    }

    std::ofstream m_out;
    std::string m_date;
    std::string m_line;
    bool m_header_done = false;
};

cairo_surface_t* make_surface(VectorFormat format, const std::string& path, double w, double h,
                              PostScriptStream* postscript)
{
    const std::tm date = creation_date();
    switch (format) {
    case VectorFormat::ps: {
        cairo_surface_t* s =
            cairo_ps_surface_create_for_stream(&PostScriptStream::write, postscript, w, h);
        // Level 2 reaches every PostScript printer and viewer; cpfg wrote plain paths too
        cairo_ps_surface_restrict_to_level(s, CAIRO_PS_LEVEL_2);
        return s;
    }
    case VectorFormat::svg: return cairo_svg_surface_create(path.c_str(), w, h);
    case VectorFormat::pdf: {
        cairo_surface_t* s = cairo_pdf_surface_create(path.c_str(), w, h);
        // PDF 1.4 keeps the page objects readable, without object streams
        cairo_pdf_surface_restrict_to_version(s, CAIRO_PDF_VERSION_1_4);
        char iso[32];
        std::strftime(iso, sizeof iso, "%Y-%m-%dT%H:%M:%SZ", &date);
        cairo_pdf_surface_set_metadata(s, CAIRO_PDF_METADATA_CREATE_DATE, iso);
        return s;
    }
    case VectorFormat::none: break;
    }
    return nullptr;
}

/// The PostScript header's date, as cairo writes it (ctime's layout), in UTC.
std::string postscript_date()
{
    const std::tm date = creation_date();
    char text[64];
    std::strftime(text, sizeof text, "%a %b %e %H:%M:%S %Y", &date);
    return text;
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
        std::unique_ptr<PostScriptStream> postscript;
        if (format == VectorFormat::ps) {
            postscript = std::make_unique<PostScriptStream>(temporary, postscript_date());
            if (!postscript->good())
                throw Error(file.string() + ": cannot write: " + std::strerror(errno));
        }
        std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
            make_surface(format, temporary.string(), drawing.width, drawing.height, postscript.get()));
        std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
        draw(cr.get(), drawing);
        cairo_show_page(cr.get());
        cairo_status_t status = cairo_status(cr.get());
        cr.reset();
        cairo_surface_finish(surface.get());
        if (status == CAIRO_STATUS_SUCCESS)
            status = cairo_surface_status(surface.get());
        if (status == CAIRO_STATUS_SUCCESS && postscript && !postscript->finish())
            status = CAIRO_STATUS_WRITE_ERROR;
        if (status != CAIRO_STATUS_SUCCESS)
            throw Error(file.string() + ": cannot write: " + cairo_status_to_string(status));
    });
}

}  // namespace cambium::render
