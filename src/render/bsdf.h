// SPDX-License-Identifier: Apache-2.0
// The BSDF of a surface point: evaluation, density and sampling. Inline: the path tracer
// calls them at every vertex, and as calls into another file their results came back
// through memory and their shared arithmetic (the lobe weights) was made twice.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "render/vecf.h"

namespace cambium::render {

/// The scattering at one surface point (docs/materials.md): three lobes summed,
///  - Lambertian reflection with albedo `reflect`,
///  - Lambertian transmission to the other side with albedo `transmit` (leaves),
///  - an energy-conserving normalized Phong lobe (Lafortune & Willems 1994)
///    f = glossy (exponent + 2) / (2 pi) cos^exponent(alpha) about the mirror direction.
/// reflect + transmit + glossy <= 1 per channel keeps every lobe's sum energy-conserving.
struct Bsdf {
    Vec3f reflect;
    Vec3f transmit;
    Vec3f glossy;
    float exponent = 0;
};

/// An ideal diffuse reflector.
inline Bsdf lambertian(const Vec3f& albedo) { return Bsdf{albedo, Vec3f(), Vec3f(), 0}; }

/// A direction sampled from a BSDF: `weight` = f |cos| / pdf, `pdf` per steradian (the
/// whole mixture's, for multiple importance sampling). pdf = 0: no direction.
struct BsdfSample {
    Vec3f wi;
    Vec3f weight;
    float pdf = 0;
};

/// One BSDF seen along wo at a point with shading normal n: what its evaluations there
/// share, made once per path vertex, where next-event estimation evaluates the BSDF once
/// per lit light and sampling once more: the mirror direction of wo and the Phong lobe's
/// normalisation (a dot product and a division that every call made again). The same
/// operations as inside each call, so every value is the same to the bit.
struct BsdfAt {
    const Bsdf& bsdf;
    Vec3f n, wo;
    Vec3f mirror;           ///< wo mirrored about n: the Phong lobe's axis
    float glossy_f = 0;     ///< (exponent + 2) / (2 pi), the lobe's normalisation in f
    bool glossy = false;    ///< the Phong lobe is not black
};
inline BsdfAt bsdf_at(const Bsdf& bsdf, const Vec3f& n, const Vec3f& wo);
/// bsdf_eval(), bsdf_pdf() and bsdf_sample() of at.bsdf at at.n and at.wo.
inline Vec3f bsdf_eval(const BsdfAt& at, const Vec3f& wi);
inline float bsdf_pdf(const BsdfAt& at, const Vec3f& wi);
inline BsdfSample bsdf_sample(const BsdfAt& at, float u1, float u2);

/// f(wo, wi); n is the shading normal on wo's side, all vectors unit.
inline Vec3f bsdf_eval(const Bsdf& bsdf, const Vec3f& n, const Vec3f& wo, const Vec3f& wi);
/// The solid-angle density bsdf_sample() draws wi with.
inline float bsdf_pdf(const Bsdf& bsdf, const Vec3f& n, const Vec3f& wo, const Vec3f& wi);
/// Draws wi from two uniforms: a lobe in proportion to its albedo, then a direction.
inline BsdfSample bsdf_sample(const Bsdf& bsdf, const Vec3f& n, const Vec3f& wo, float u1,
                              float u2);

// ---- Implementation -------------------------------------------------------------------

namespace bsdf_detail {

inline constexpr float pi = std::numbers::pi_v<float>;
inline constexpr float inv_pi = std::numbers::inv_pi_v<float>;

inline float mean(const Vec3f& v) { return (v.x + v.y + v.z) / 3; }

/// The cosine and sine of `turns` whole turns (an angle of 2 pi turns), turns in [0, 1]:
/// Taylor polynomials on the nearest quarter turn's eighth either side, within 1.2e-7 of
/// std::cos and std::sin (float rounding). Inline, where those two made a libm call
/// (sincosf, through the PLT) at every BSDF sample.
inline std::array<float, 2> cos_sin_turns(float turns)
{
    float x = 4 * turns;  // in quarter turns
    int quarter = static_cast<int>(x + 0.5f);
    float a = (x - static_cast<float>(quarter)) * (pi / 2);  // exact difference; |a| <= pi/4
    // Paired terms (Estrin's scheme), not one chain (Horner's): the direction waits on
    // these, and half as many steps follow each other.
    float a2 = a * a, a4 = a2 * a2;
    float s = a * ((1 - a2 * (1.0f / 6)) +
                   a4 * ((1.0f / 120 - a2 * (1.0f / 5040)) + a4 * (1.0f / 362880)));
    float c = (1 - a2 * 0.5f) + a4 * ((1.0f / 24 - a2 * (1.0f / 720)) + a4 * (1.0f / 40320));
    // Turned by `quarter` quarter turns: (c, s) -> (-s, c) each.
    bool odd = (quarter & 1) != 0;
    float cos = odd ? s : c, sin = odd ? c : s;
    return {(quarter + 1) & 2 ? -cos : cos, quarter & 2 ? -sin : sin};
}

/// A direction about the unit axis a at the angle whose cosine and sine are given, turned
/// `turns` whole turns about a.
inline Vec3f around(const Vec3f& a, float cos_theta, float sin_theta, float turns)
{
    Vec3f t, b;
    make_basis(a, t, b);
    auto [cos_phi, sin_phi] = cos_sin_turns(turns);
    // (t, b, a) is orthonormal and sin^2 + cos^2 = 1 in both angles, so the sum is a unit
    // vector to float rounding: normalising it again (a square root and a division in
    // every BSDF sample's dependency chain) changed nothing but the rounding.
    return t * (sin_theta * cos_phi) + b * (sin_theta * sin_phi) + a * cos_theta;
}

/// A direction about the unit axis a with cos(angle to a) = cos_theta.
inline Vec3f around(const Vec3f& a, float cos_theta, float turns)
{
    // std::max(0, x) is std::fmax(0, x) for any x, NaN too, without a libm call.
    return around(a, cos_theta, std::sqrt(std::max(0.0f, 1 - cos_theta * cos_theta)), turns);
}

/// Cosine-weighted direction about n: cos^2 = 1 - u1, so sin^2 = u1. (Both roots at once,
/// not the sine from the rounded cosine: shorter, and exact near the normal.)
inline Vec3f sample_cosine(const Vec3f& n, float u1, float u2)
{
    return around(n, std::sqrt(std::max(0.0f, 1 - u1)), std::sqrt(std::max(0.0f, u1)), u2);
}

inline Vec3f mirror(const Vec3f& wo, const Vec3f& n) { return n * (2 * dot(n, wo)) - wo; }

/// The lobes' selection probabilities, in proportion to their mean albedo.
struct LobeWeights {
    float reflect = 0, transmit = 0, glossy = 0;
};

inline LobeWeights lobe_weights(const Bsdf& b)
{
    float r = mean(b.reflect), t = mean(b.transmit), g = mean(b.glossy);
    float sum = r + t + g;
    if (sum <= 0)
        return {};
    return {r / sum, t / sum, g / sum};
}

/// c^e for c in (0, 1] and e > 0. A cpfg material's exponent is its shininess (an
/// integer to 128) / 4, so e is a whole number of quarters, q / 4: then c^e is
/// (c^(1/4))^q, made in double from square roots and a product of squares, and rounded
/// once to float. Its error before that rounding is below 300 double roundings (1e-13
/// relative, against float's half unit 6e-8), so it is the correctly rounded c^e but
/// where the exact value lies within 1e-13 of a rounding boundary (the test found none in
/// 2 M; glibc's powf, the float std::pow used here before, is an ulp off in 1 in 1000).
/// Inline and without libm's logarithm and exponential, where powf (a call through the
/// PLT) was a twentieth of a leafy plant's trace. Other exponents (blended materials) go
/// to std::pow.
inline float power(float c, float e)
{
    float quarters = e * 4;  // exact: a power of two
    if (!(quarters <= 512) || quarters != static_cast<float>(static_cast<int>(quarters)))
        return std::pow(c, e);
    const int q = static_cast<int>(quarters);
    double x = c, p = 1;
    switch (q & 3) {  // the quarters' part first: c^(1/4), c^(1/2), c^(3/4)
    case 1: p = std::sqrt(std::sqrt(x)); break;
    case 2: p = std::sqrt(x); break;
    case 3: {
        double r = std::sqrt(x);
        p = r * std::sqrt(r);
        break;
    }
    default: break;
    }
    for (int m = q >> 2; m != 0; m >>= 1) {  // then c^(q div 4) by squaring
        if (m & 1)
            p *= x;
        x *= x;
    }
    return static_cast<float>(p);
}

/// cos^exponent of the angle between wi and the mirror direction `axis` (0 behind it).
inline float phong_about(const Bsdf& b, const Vec3f& axis, const Vec3f& wi)
{
    float c = dot(axis, wi);
    if (c <= 0)
        return 0;
    return b.exponent > 0 ? power(c, b.exponent) : 1.0f;
}

/// cos^exponent of the angle between wi and the mirror direction (0 behind it).
inline float phong_term(const Bsdf& b, const Vec3f& n, const Vec3f& wo, const Vec3f& wi)
{
    return phong_about(b, mirror(wo, n), wi);
}

/// The Phong lobe's share of the pdf per unit of its term: w.glossy (exponent + 1) / (2 pi).
inline float glossy_pdf_scale(const Bsdf& b, const LobeWeights& w)
{
    return w.glossy * (b.exponent + 1) / (2 * pi);
}

/// bsdf_pdf() with the lobes' selection probabilities already made.
inline float pdf_with(const BsdfAt& at, const LobeWeights& w, const Vec3f& wi)
{
    float cos_i = dot(at.n, wi);
    if (cos_i < 0)
        return w.transmit * -cos_i * inv_pi;
    float p = w.reflect * cos_i * inv_pi;
    if (w.glossy > 0)
        p += glossy_pdf_scale(at.bsdf, w) * phong_about(at.bsdf, at.mirror, wi);
    return p;
}

/// bsdf_eval() and pdf_with() of one direction together, for bsdf_sample(): the same
/// values, with the Phong term (the costly part of both) made once.
struct EvalPdf {
    Vec3f f;
    float pdf = 0;
};

inline EvalPdf eval_pdf_with(const BsdfAt& at, const LobeWeights& w, const Vec3f& wi)
{
    const Bsdf& b = at.bsdf;
    float cos_i = dot(at.n, wi);
    if (cos_i < 0)
        return {b.transmit * inv_pi, w.transmit * -cos_i * inv_pi};
    const bool glossy_pdf = w.glossy > 0;
    const float phong = at.glossy || glossy_pdf ? phong_about(b, at.mirror, wi) : 0.0f;
    Vec3f f = b.reflect * inv_pi;
    if (at.glossy)
        f += b.glossy * (at.glossy_f * phong);
    float p = w.reflect * cos_i * inv_pi;
    if (glossy_pdf)
        p += glossy_pdf_scale(b, w) * phong;
    return {f, p};
}

/// Whether the BSDF only reflects diffusely (most surfaces): its lobe weights are then
/// (1, 0, 0) when it reflects at all, exactly what lobe_weights() computes (r / r), and
/// sampling needs none of their divisions.
inline bool diffuse_only(const Bsdf& b) { return is_black(b.transmit) && is_black(b.glossy); }

/// bsdf_sample() of a diffuse_only() BSDF: the same directions and densities as with
/// weights (1, 0, 0), and the weight f cos / pdf = (reflect / pi) cos / (cos / pi) as the
/// albedo itself (the general path's division gives it to rounding, and the path's
/// throughput waited on that division).
inline BsdfSample sample_diffuse(const Bsdf& b, const Vec3f& n, float u1, float u2)
{
    if (!(mean(b.reflect) > 0) || !(u1 < 1))
        return {};
    Vec3f wi = sample_cosine(n, u1, u2);
    float cos_i = dot(n, wi);
    float pdf = cos_i < 0 ? 0.0f : cos_i * inv_pi;
    if (pdf <= 0)
        return {};
    return {wi, b.reflect, pdf};
}

}  // namespace bsdf_detail

inline BsdfAt bsdf_at(const Bsdf& b, const Vec3f& n, const Vec3f& wo)
{
    using namespace bsdf_detail;
    const bool glossy = !is_black(b.glossy);
    return {b, n, wo, mirror(wo, n), glossy ? (b.exponent + 2) / (2 * pi) : 0.0f, glossy};
}

inline Vec3f bsdf_eval(const BsdfAt& at, const Vec3f& wi)
{
    using namespace bsdf_detail;
    const Bsdf& b = at.bsdf;
    float cos_i = dot(at.n, wi);
    if (cos_i < 0)
        return b.transmit * inv_pi;
    Vec3f f = b.reflect * inv_pi;
    if (at.glossy)
        f += b.glossy * (at.glossy_f * phong_about(b, at.mirror, wi));
    return f;
}

inline float bsdf_pdf(const BsdfAt& at, const Vec3f& wi)
{
    return bsdf_detail::pdf_with(at, bsdf_detail::lobe_weights(at.bsdf), wi);
}

// Always inline: GCC made it a call, whose result came back through memory, and the
// caller's 8-byte load of weight.x and .y spanned two of its stores (a 16-byte and an
// 8-byte one), which stalls store forwarding at every vertex; an empty result was zeroed
// by `rep stos` for a caller that reads only its pdf.
[[gnu::always_inline]] inline BsdfSample bsdf_sample(const BsdfAt& at, float u1, float u2)
{
    using namespace bsdf_detail;
    const Bsdf& b = at.bsdf;
    const Vec3f& n = at.n;
    if (diffuse_only(b))
        return sample_diffuse(b, n, u1, u2);
    LobeWeights w = lobe_weights(b);
    Vec3f wi;
    const bool reflect = u1 < w.reflect;
    if (reflect | (u1 < w.reflect + w.transmit)) {
        // Either Lambertian lobe, picked by selects, not a branch: on a translucent leaf
        // which one is a coin flip, a branch mispredicted half the time. The same values
        // as one branch per lobe: u1 - 0 is u1, and the axis is n or n negated.
        const float below = reflect ? 0.0f : w.reflect;
        const float share = reflect ? w.reflect : w.transmit;
        const float side = reflect ? 1.0f : -1.0f;
        wi = sample_cosine(n * side, (u1 - below) / share, u2);
    } else if (w.glossy > 0) {
        // min(x, 1) by hand, as std::fmin gives it for every x (NaN too), where std::fmin
        // is a library call.
        const float x = (u1 - w.reflect - w.transmit) / w.glossy;
        const float u = x < 1 ? x : 1.0f;
        // pdf (n+1)/(2 pi) cos^n about the mirror direction: cos = u^(1/(n+1)).
        float cos_a = std::pow(u, 1 / (b.exponent + 1));
        wi = around(at.mirror, cos_a, u2);
        if (dot(n, wi) <= 0)
            return {};  // below the surface: the lobe's lost energy
    } else {
        return {};
    }
    const EvalPdf e = eval_pdf_with(at, w, wi);
    if (e.pdf <= 0)
        return {};
    return {wi, e.f * (std::fabs(dot(n, wi)) / e.pdf), e.pdf};
}

inline Vec3f bsdf_eval(const Bsdf& b, const Vec3f& n, const Vec3f& wo, const Vec3f& wi)
{
    return bsdf_eval(bsdf_at(b, n, wo), wi);
}

inline float bsdf_pdf(const Bsdf& b, const Vec3f& n, const Vec3f& wo, const Vec3f& wi)
{
    return bsdf_pdf(bsdf_at(b, n, wo), wi);
}

inline BsdfSample bsdf_sample(const Bsdf& b, const Vec3f& n, const Vec3f& wo, float u1, float u2)
{
    return bsdf_sample(bsdf_at(b, n, wo), u1, u2);
}

}  // namespace cambium::render
