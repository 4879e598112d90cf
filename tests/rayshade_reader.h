// SPDX-License-Identifier: Apache-2.0
// A small reader of the rayshade 4.0 subset cpfg writes, for tests: surfaces, view,
// lights and every primitive of the main object in world coordinates (named objects
// expanded through their transforms).
#pragma once

#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cambium::test {

using RayPoint = std::array<double, 3>;

struct RayPrimitive {
    enum Kind { cylinder, sphere, disc, facet };
    Kind kind = cylinder;
    /// cylinder: base, apex; sphere, disc: centre (and the disc's normal)
    std::array<RayPoint, 2> p{};
    std::vector<RayPoint> corners;      ///< facet (triangle or polygon): its corners
    std::array<double, 2> radius{};     ///< cylinder: base, apex; sphere/disc: [0]
    std::string surface;                ///< "" when none applies
};

struct RaySurface {
    RayPoint ambient{}, diffuse{};
};

struct RayLight {
    std::string kind;  ///< ambient, directional, point, spot
    RayPoint colour{};
};

struct RayScene {
    std::map<std::string, RaySurface> surfaces;
    RayPoint eyep{}, lookp{}, up{}, background{};
    double fov = 0;
    std::vector<RayLight> lights;
    std::optional<std::array<double, 6>> box;  ///< the BBOX block's box
    std::vector<RayPrimitive> primitives;      ///< of the top-level object(s), in world space
    /// Objects placed but defined in no file read (cpfg's `@I` includes another file's).
    std::vector<std::string> external_objects;
};

namespace ray_detail {

/// x' = a x + t (column vectors).
struct Affine {
    std::array<std::array<double, 3>, 3> a{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    RayPoint t{};
    RayPoint apply(const RayPoint& p) const
    {
        RayPoint r{};
        for (int i = 0; i < 3; ++i)
            r[i] = a[i][0] * p[0] + a[i][1] * p[1] + a[i][2] * p[2] + t[i];
        return r;
    }
    /// This, then `next`.
    Affine then(const Affine& next) const
    {
        Affine r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                r.a[i][j] = next.a[i][0] * a[0][j] + next.a[i][1] * a[1][j] + next.a[i][2] * a[2][j];
        r.t = next.apply(t);
        return r;
    }
    double radius_scale() const
    {
        double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                     a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
        return std::cbrt(std::fabs(det));
    }
};

struct Placement {
    std::string object, surface;
    Affine transform;
};

struct Definition {
    std::vector<RayPrimitive> primitives;
    std::vector<Placement> placements;
};

class Reader {
public:
    explicit Reader(const std::string& text) { tokenize(text); }

    RayScene read()
    {
        RayScene& scene = m_scene;
        std::vector<Placement> top;
        while (m_at < m_words.size()) {
            std::string w = next();
            if (w == "surface")
                read_surface(scene);
            else if (w == "eyep")
                scene.eyep = point();
            else if (w == "lookp")
                scene.lookp = point();
            else if (w == "up")
                scene.up = point();
            else if (w == "fov") {
                scene.fov = number();
                if (is_number())
                    number();
            } else if (w == "screen") {
                number();
                number();
            } else if (w == "background")
                scene.background = point();
            else if (w == "light")
                read_light(scene);
            else if (w == "box") {
                std::array<double, 6> b{};
                for (double& v : b)
                    v = number();
                scene.box = b;
            } else if (w == "name")
                read_definition();
            else if (w == "object")
                top.push_back(placement());
            else if (w == "grid" || w == "list")
                skip_numbers();
            else
                throw std::runtime_error("rayshade reader: unexpected '" + w + "'");
        }
        for (const Placement& p : top)
            expand(p, scene.primitives, 0);
        return std::move(scene);
    }

private:
    void tokenize(const std::string& text)
    {
        std::istringstream lines(text);
        std::string line;
        std::vector<bool> skipping;
        bool in_comment = false;
        while (std::getline(lines, line)) {
            std::istringstream ws(line);
            std::string first;
            ws >> first;
            if (first == "#ifdef") {
                std::string macro;
                ws >> macro;
                skipping.push_back(true);  // no macro is defined: BBOX, NOSURFACES... are off
                continue;
            }
            if (first == "#ifndef") {
                skipping.push_back(false);
                continue;
            }
            if (first == "#else") {
                if (!skipping.empty())
                    skipping.back() = !skipping.back();
                continue;
            }
            if (first == "#endif") {
                if (!skipping.empty())
                    skipping.pop_back();
                continue;
            }
            bool skip = false;
            for (bool s : skipping)
                skip = skip || s;
            if (skip)
                continue;
            std::istringstream words(line);
            for (std::string w; words >> w;) {
                if (in_comment) {
                    if (w.find("*/") != std::string::npos)
                        in_comment = false;
                    continue;
                }
                if (w.rfind("/*", 0) == 0) {
                    in_comment = w.find("*/", 2) == std::string::npos;
                    continue;
                }
                m_words.push_back(w);
            }
        }
    }
    std::string next()
    {
        if (m_at >= m_words.size())
            throw std::runtime_error("rayshade reader: unexpected end");
        return m_words[m_at++];
    }
    bool is_number() const
    {
        if (m_at >= m_words.size())
            return false;
        const std::string& w = m_words[m_at];
        char* end = nullptr;
        std::strtod(w.c_str(), &end);
        return !w.empty() && end == w.c_str() + w.size();
    }
    double number()
    {
        if (!is_number())
            throw std::runtime_error("rayshade reader: expected a number, not '" +
                                     (m_at < m_words.size() ? m_words[m_at] : std::string("end")) + "'");
        return std::strtod(m_words[m_at++].c_str(), nullptr);
    }
    RayPoint point() { return {number(), number(), number()}; }
    void skip_numbers()
    {
        while (is_number())
            ++m_at;
    }
    /// A colour: one grey number or three.
    RayPoint colour()
    {
        double r = number();
        if (!is_number())
            return {r, r, r};
        return {r, number(), number()};
    }
    std::string optional_surface()
    {
        if (is_number())
            return {};
        return next();
    }
    void read_surface(RayScene& scene)
    {
        RaySurface& s = scene.surfaces[next()];
        while (m_at < m_words.size()) {
            const std::string& w = m_words[m_at];
            if (w == "ambient") {
                ++m_at;
                s.ambient = colour();
            } else if (w == "diffuse") {
                ++m_at;
                s.diffuse = colour();
            } else if (w == "specular" || w == "body") {
                ++m_at;
                colour();
            } else if (w == "specpow" || w == "transp" || w == "index" || w == "reflect" ||
                       w == "extinct" || w == "translu") {
                ++m_at;
                skip_numbers();
            } else {
                break;
            }
        }
    }
    void read_light(RayScene& scene)
    {
        RayLight l;
        l.colour = colour();
        l.kind = next();
        skip_numbers();
        scene.lights.push_back(l);
    }
    Affine transforms()
    {
        Affine total;
        while (m_at < m_words.size()) {
            const std::string& w = m_words[m_at];
            Affine step;
            if (w == "scale") {
                ++m_at;
                RayPoint s = point();
                for (int i = 0; i < 3; ++i)
                    step.a[i][i] = s[i];
            } else if (w == "translate") {
                ++m_at;
                step.t = point();
            } else if (w == "rotate") {
                ++m_at;
                RayPoint k = point();
                double angle = number() * std::numbers::pi / 180;
                double len = std::hypot(k[0], k[1], k[2]);
                for (double& v : k)
                    v /= len;
                double c = std::cos(angle), s = std::sin(angle);
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j)
                        step.a[i][j] = (i == j ? c : 0) + (1 - c) * k[i] * k[j];
                step.a[0][1] -= s * k[2];
                step.a[0][2] += s * k[1];
                step.a[1][0] += s * k[2];
                step.a[1][2] -= s * k[0];
                step.a[2][0] -= s * k[1];
                step.a[2][1] += s * k[0];
            } else if (w == "transform") {
                ++m_at;
                // rayshade's rows are the images of the axes (row vectors times the matrix)
                for (int row = 0; row < 3; ++row)
                    for (int col = 0; col < 3; ++col)
                        step.a[col][row] = number();
                if (is_number())
                    step.t = point();
            } else {
                break;
            }
            total = total.then(step);
        }
        return total;
    }
    Placement placement()
    {
        Placement p;
        std::string first = next();
        if (m_definitions.count(first) == 0 && !is_number() && m_at < m_words.size() &&
            m_definitions.count(m_words[m_at])) {
            p.surface = first;  // object SURFACE NAME
            first = next();
        }
        p.object = first;
        p.transform = transforms();
        return p;
    }
    void read_definition()
    {
        std::string name = next();
        Definition d;
        std::string current;  // applysurf
        while (true) {
            std::string w = next();
            if (w == "end")
                break;
            if (w == "grid" || w == "list") {
                skip_numbers();
            } else if (w == "applysurf") {
                current = next();
            } else if (w == "surface") {
                read_surface(m_scene);  // cpfg defines a surface where it first needs it
            } else if (w == "object") {
                Placement p = placement();
                if (p.surface.empty())
                    p.surface = current;
                d.placements.push_back(p);
            } else if (w == "cylinder" || w == "cone") {
                RayPrimitive c;
                c.surface = optional_surface();
                c.radius[0] = number();
                c.p[0] = point();
                c.radius[1] = w == "cone" ? number() : c.radius[0];
                c.p[1] = point();
                add(d, c, current);
            } else if (w == "sphere") {
                RayPrimitive s;
                s.kind = RayPrimitive::sphere;
                s.surface = optional_surface();
                s.radius[0] = number();
                s.p[0] = point();
                add(d, s, current);
            } else if (w == "disc") {
                RayPrimitive s;
                s.kind = RayPrimitive::disc;
                s.surface = optional_surface();
                s.radius[0] = number();
                s.p[0] = point();
                s.p[1] = point();
                add(d, s, current);
            } else if (w == "poly" || w == "polygon") {
                RayPrimitive f;
                f.kind = RayPrimitive::facet;
                f.surface = optional_surface();
                while (is_number())
                    f.corners.push_back(point());
                if (f.corners.size() > 3 && f.corners.front() == f.corners.back())
                    f.corners.pop_back();  // cpfg repeats the first vertex
                add(d, f, current);
            } else if (w == "triangle" || w == "triangleuv") {
                RayPrimitive t;
                t.kind = RayPrimitive::facet;
                t.surface = optional_surface();
                std::vector<double> n;
                while (is_number())
                    n.push_back(number());
                std::size_t per = n.size() / 3;
                if (n.size() % 3 != 0 || (per != 3 && per != 6 && per != 8))
                    throw std::runtime_error("rayshade reader: a triangle of " + std::to_string(n.size()) +
                                             " numbers");
                for (std::size_t k = 0; k < 3; ++k)
                    t.corners.push_back({n[k * per], n[k * per + 1], n[k * per + 2]});
                add(d, t, current);
            } else {
                throw std::runtime_error("rayshade reader: unexpected '" + w + "' in object " + name);
            }
        }
        m_definitions[name] = d;
    }
    static void add(Definition& d, RayPrimitive p, const std::string& current)
    {
        if (p.surface.empty())
            p.surface = current;
        d.primitives.push_back(p);
    }
    void expand(const Placement& at, std::vector<RayPrimitive>& out, int depth)
    {
        if (depth > 16)
            throw std::runtime_error("rayshade reader: objects nested too deep at " + at.object);
        auto it = m_definitions.find(at.object);
        if (it == m_definitions.end()) {
            m_scene.external_objects.push_back(at.object);
            return;
        }
        double rs = at.transform.radius_scale();
        for (RayPrimitive p : it->second.primitives) {
            if (p.surface.empty())
                p.surface = at.surface;
            if (p.kind == RayPrimitive::disc) {
                RayPoint tip = at.transform.apply({p.p[0][0] + p.p[1][0], p.p[0][1] + p.p[1][1],
                                                   p.p[0][2] + p.p[1][2]});
                p.p[0] = at.transform.apply(p.p[0]);
                p.p[1] = {tip[0] - p.p[0][0], tip[1] - p.p[0][1], tip[2] - p.p[0][2]};
            } else if (p.kind == RayPrimitive::facet) {
                for (RayPoint& c : p.corners)
                    c = at.transform.apply(c);
            } else {
                int n = p.kind == RayPrimitive::cylinder ? 2 : 1;
                for (int k = 0; k < n; ++k)
                    p.p[k] = at.transform.apply(p.p[k]);
            }
            p.radius[0] *= rs;
            p.radius[1] *= rs;
            out.push_back(p);
        }
        for (Placement inner : it->second.placements) {
            inner.transform = inner.transform.then(at.transform);
            if (inner.surface.empty())
                inner.surface = at.surface;
            expand(inner, out, depth + 1);
        }
    }

    RayScene m_scene;
    std::vector<std::string> m_words;
    std::size_t m_at = 0;
    std::map<std::string, Definition> m_definitions;
};

}  // namespace ray_detail

/// Reads a rayshade file's text; throws std::runtime_error on what it does not know.
inline RayScene read_rayshade(const std::string& text) { return ray_detail::Reader(text).read(); }

}  // namespace cambium::test
