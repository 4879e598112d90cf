// SPDX-License-Identifier: Apache-2.0
// Interprets an L-system string with the turtle and builds the renderer-independent Scene.
#include "geom/interpreter.h"

#include <algorithm>
#include <vector>

#include "geom/turtle.h"

namespace cambium::geom {
namespace {

/// The turtle operation of every symbol of a table, looked up by name once.
std::vector<TurtleOp> symbol_ops(const lsys::SymbolTable& symbols)
{
    std::vector<TurtleOp> ops(symbols.size(), TurtleOp::None);
    auto bind = [&](const char* name, TurtleOp op) {
        int id = symbols.find(name);
        if (id >= 0)
            ops[static_cast<std::size_t>(id)] = op;
    };
#define X(op, name, doc) bind(name, TurtleOp::op);
#include "geom/turtle_symbols.def"
#undef X
    return ops;
}

/// One pass of the turtle over the string, cpfg's interpret.c semantics.
///
/// A segment's top width is the turtle's width when the segment ends, at the next
/// "node" (F f G g [ ] and the end of the string), so `F!F` tapers its first segment
/// (`tapered lines: on`, cpfg's default). Consecutive segments share their joint key,
/// which carries that width, and get Embree's neighbour flags.
class Interpreter {
public:
    explicit Interpreter(const ViewFile& view) : m_view(view)
    {
        m_turtle.line_width = view.initial_line_width;
        m_turtle.color = view.initial_color;
        m_turtle.back_color = view.initial_back_color;
        m_turtle.scale = view.initial_scale;
        m_scene.line_radius_in_pixels = view.line_style == LineStyle::pixel;
        m_scene.view = view.view;
        m_scene.lights = effective_lights(view);
        m_scene.bounds.extend(Vec3{0, 0, 0});  // cpfg's box always holds the origin
    }

    void run(const lsys::ModuleString& string, const lsys::SymbolTable& symbols)
    {
        std::vector<TurtleOp> ops = symbol_ops(symbols);
        string.for_each([&](lsys::ModuleRef m) { apply(ops[m.symbol], m.params); });
        end_node();
    }

    Scene take() { return std::move(m_scene); }

private:
    double angle(std::span<const float> p) const
    {
        return p.empty() ? m_view.angle_increment_deg : static_cast<double>(p[0]);
    }

    double length(std::span<const float> p) const
    {
        return (p.empty() ? 1.0 : static_cast<double>(p[0])) * m_turtle.scale;
    }

    void apply(TurtleOp op, std::span<const float> p)
    {
        switch (op) {
        case TurtleOp::None: break;
        case TurtleOp::Forward:
        case TurtleOp::ForwardG: draw_forward(length(p)); break;
        case TurtleOp::ForwardNoDraw:
        case TurtleOp::ForwardGNoDraw: move_forward(length(p)); break;
        case TurtleOp::TurnLeft: m_turtle.turn(angle(p)); break;
        case TurtleOp::TurnRight: m_turtle.turn(-angle(p)); break;
        case TurtleOp::PitchDown: m_turtle.pitch(angle(p)); break;
        case TurtleOp::PitchUp: m_turtle.pitch(-angle(p)); break;
        case TurtleOp::RollRight: m_turtle.roll(angle(p)); break;
        case TurtleOp::RollLeft: m_turtle.roll(-angle(p)); break;
        case TurtleOp::TurnAround: m_turtle.turn_around(); break;
        case TurtleOp::Push: push(); break;
        case TurtleOp::Pop: pop(); break;
        case TurtleOp::WidthUp: change_width(p, +1); break;
        case TurtleOp::WidthDown: change_width(p, -1); break;
        case TurtleOp::ColorUp: change_color(p, +1); break;
        case TurtleOp::ColorDown: change_color(p, -1); break;
        }
    }

    /// Ends the current node: the last segment's top width is now fixed, and the
    /// turtle's position goes into the bounding box as cpfg's viewVol.c records it.
    void end_node()
    {
        m_taper_open = false;
        m_scene.bounds.extend(m_turtle.position);
    }

    void push()
    {
        end_node();
        m_stack.push_back(m_turtle);
    }

    void pop()
    {
        end_node();
        if (m_stack.empty()) {
            if (!m_warned_unbalanced)
                warn("unmatched ']' in the string ignored");
            m_warned_unbalanced = true;
            return;
        }
        m_turtle = m_stack.back();
        m_stack.pop_back();
        m_chain_open = false;
    }

    /// `#` and `!`: by the view file's increment, or set to the parameter; at least 1e-7.
    void change_width(std::span<const float> p, int sign)
    {
        double width = p.empty() ? m_turtle.line_width + sign * m_view.line_width_increment * m_turtle.scale
                                 : static_cast<double>(p[0]) * m_turtle.scale;
        width = std::max(width, 1e-7);
        if (width == m_turtle.line_width)
            return;
        m_turtle.line_width = width;
        if (m_taper_open && tapers())
            m_scene.geometry.lines.keys.back()[3] = radius();  // the open segment's top
        else
            m_chain_open = false;  // the joint key cannot carry two widths
    }

    /// `;` and `,`: by the increment (wrapping once around the 256 entries) or set.
    void change_color(std::span<const float> p, int sign)
    {
        int color = p.empty() ? m_turtle.color + sign * m_view.color_increment : static_cast<int>(p[0]);
        if (color > 255)
            color -= 256;
        if (color < 0)
            color += 256;
        m_turtle.color = color;
    }

    bool tapers() const { return m_view.tapered_lines && !m_scene.line_radius_in_pixels; }

    float radius() const { return static_cast<float>(0.5 * m_turtle.line_width); }

    void move_forward(double distance)
    {
        end_node();
        m_turtle.position += m_turtle.heading * distance;
        m_chain_open = false;
    }

    /// Draws one cylinder segment, continuing the current polyline when the turtle
    /// has drawn without interruption, so Embree closes the joint.
    void draw_forward(double distance)
    {
        end_node();
        Vec3 start = m_turtle.position;
        m_turtle.position += m_turtle.heading * distance;
        LinearCurves& lines = m_scene.geometry.lines;
        bool joined = m_chain_open;
        if (!joined)
            lines.keys.push_back(key(start, radius()));
        auto first = static_cast<std::uint32_t>(lines.keys.size() - 1);
        lines.keys.push_back(key(m_turtle.position, radius()));
        if (joined)
            lines.flags.back() |= LinearCurves::neighbour_right;
        lines.segments.push_back(first);
        lines.flags.push_back(joined ? LinearCurves::neighbour_left : 0);
        lines.material.push_back(static_cast<std::uint16_t>(std::clamp(m_turtle.color, 0, 255)));
        m_chain_open = true;
        m_taper_open = true;
    }

    static std::array<float, 4> key(const Vec3& p, float radius)
    {
        return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), radius};
    }

    const ViewFile& m_view;
    Scene m_scene;
    Turtle m_turtle;
    std::vector<Turtle> m_stack;
    bool m_chain_open = false;  ///< the last key is at the turtle and may be shared
    bool m_taper_open = false;  ///< the last segment's top width may still change
    bool m_warned_unbalanced = false;
};

}  // namespace

std::vector<Light> effective_lights(const ViewFile& view)
{
    if (!view.lights.empty())
        return view.lights;
    // cpfg's default: a white directional light toward `light direction:`, (1,0,0).
    Light light;
    light.kind = Light::Kind::directional;
    light.direction = normalize(view.light_direction.value_or(Vec3{1, 0, 0}));
    return {light};
}

Scene interpret(const lsys::ModuleString& string, const lsys::SymbolTable& symbols,
                const ViewFile& view)
{
    Interpreter interpreter(view);
    interpreter.run(string, symbols);
    return interpreter.take();
}

}  // namespace cambium::geom
