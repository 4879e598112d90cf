// SPDX-License-Identifier: Apache-2.0
// EmbreeScene: the Scene's primitives in Embree (the only user of <embree3/rtcore.h>).
#include "render/accel.h"

#include <embree3/rtcore.h>

#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include "base/diagnostics.h"

namespace cambium::render {

namespace {

const char* error_name(RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE: return "no error";
    case RTC_ERROR_UNKNOWN: return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
    }
    return "error";
}

/// Embree's messages: remembered (the build throws the first one) and warned about.
struct ErrorSink {
    std::mutex mutex;
    std::string first;

    static void callback(void* user, RTCError code, const char* text)
    {
        auto* sink = static_cast<ErrorSink*>(user);
        std::string message = std::string("Embree: ") + error_name(code) +
                              (text && *text ? std::string(": ") + text : std::string());
        {
            std::lock_guard lock(sink->mutex);
            if (sink->first.empty())
                sink->first = message;
        }
        warn(message);
    }
};

using Key = std::array<float, 4>;

/// An intersection context that carries the primitive to ignore (Embree 3 passes the
/// context to the context filter function, so it may be extended C-style).
struct SkipContext {
    RTCIntersectContext context;
    PrimId skip;
};

void skip_filter(const RTCFilterFunctionNArguments* args)
{
    const auto* ctx = reinterpret_cast<const SkipContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0)
            continue;
        if (RTCHitN_geomID(args->hit, args->N, i) == ctx->skip.geom &&
            RTCHitN_primID(args->hit, args->N, i) == ctx->skip.prim)
            args->valid[i] = 0;
    }
}

SkipContext make_context(PrimId skip, bool coherent)
{
    SkipContext c;
    rtcInitIntersectContext(&c.context);
    c.context.flags =
        coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    if (skip.geom != PrimId::none)
        c.context.filter = &skip_filter;
    c.skip = skip;
    return c;
}

}  // namespace

struct EmbreeScene::Impl {
    ErrorSink errors;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    const geom::LinearCurves* lines = nullptr;
    /// Keys with world-unit radii when the Scene's are in pixels (else empty: shared).
    std::vector<Key> world_keys;
    bool lines_unlit = false;  ///< pixel-style lines: flat colour, no shading
    const Key* keys = nullptr;
    std::uint32_t lines_geom_id = RTC_INVALID_GEOMETRY_ID;

    ~Impl()
    {
        if (scene)
            rtcReleaseScene(scene);
        if (device)
            rtcReleaseDevice(device);
    }

    void check(const char* what)
    {
        std::lock_guard lock(errors.mutex);
        if (!errors.first.empty())
            throw Error(std::string(what) + ": " + errors.first);
    }

    void add_lines(const geom::Scene& s, const Camera& camera);
};

namespace {

/// The segments' keys with radii converted from pixels to world units at each key's depth.
std::vector<Key> keys_in_world_units(const geom::LinearCurves& lines, const Camera& camera)
{
    std::vector<Key> keys(lines.keys);
    for (Key& k : keys)
        k[3] = static_cast<float>(k[3] * camera.pixel_size_at({k[0], k[1], k[2]}));
    return keys;
}

}  // namespace

void EmbreeScene::Impl::add_lines(const geom::Scene& s, const Camera& camera)
{
    const geom::LinearCurves& l = s.geometry.lines;
    lines = &l;
    if (l.segments.empty())
        return;
    for (std::uint32_t first : l.segments)
        if (first + 1 >= l.keys.size())
            throw Error("scene: curve segment starts at key " + std::to_string(first) +
                        " of " + std::to_string(l.keys.size()));
    lines_unlit = s.line_radius_in_pixels;
    if (s.line_radius_in_pixels) {
        world_keys = keys_in_world_units(l, camera);
        keys = world_keys.data();
    } else {
        keys = l.keys.data();
    }

    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, keys, 0,
                               sizeof(Key), l.keys.size());
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                               l.segments.data(), 0, sizeof(std::uint32_t), l.segments.size());
    // Neighbour flags close the joints of a polyline without caps or bulges.
    if (l.flags.size() == l.segments.size())
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR,
                                   l.flags.data(), 0, sizeof(std::uint8_t), l.flags.size());
    else if (!l.flags.empty())
        warn("scene: " + std::to_string(l.flags.size()) + " curve flags for " +
             std::to_string(l.segments.size()) + " segments; flags ignored");
    rtcCommitGeometry(g);
    lines_geom_id = rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

EmbreeScene::EmbreeScene(const geom::Scene& scene, const Camera& camera)
    : m_impl(std::make_unique<Impl>())
{
    Impl& m = *m_impl;
    m.device = rtcNewDevice(nullptr);
    if (!m.device)
        throw Error(std::string("Embree: cannot create a device: ") +
                    error_name(rtcGetDeviceError(nullptr)));
    rtcSetDeviceErrorFunction(m.device, &ErrorSink::callback, &m.errors);
    m.scene = rtcNewScene(m.device);
    rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_HIGH);
    m.add_lines(scene, camera);
    rtcCommitScene(m.scene);
    m.check("building the Embree scene");
}

EmbreeScene::~EmbreeScene() = default;

std::size_t EmbreeScene::segment_count() const
{
    return m_impl->lines ? m_impl->lines->segments.size() : 0;
}

std::optional<SurfaceHit> EmbreeScene::intersect(const Vec3f& org, const Vec3f& dir, float tnear,
                                                 float tfar, PrimId skip, bool coherent) const
{
    const Impl& m = *m_impl;
    SkipContext context = make_context(skip, coherent);
    RTCRayHit rh;
    rh.ray.org_x = org.x;
    rh.ray.org_y = org.y;
    rh.ray.org_z = org.z;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.time = 0;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m.scene, &context.context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return std::nullopt;

    SurfaceHit h;
    h.t = rh.ray.tfar;
    h.position = org + dir * h.t;
    Vec3f n = normalize(Vec3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    h.normal = dot(n, dir) > 0 ? -n : n;
    h.geom_id = rh.hit.geomID;
    h.prim_id = rh.hit.primID;
    // One geometry so far: the linear curves.
    const geom::LinearCurves& l = *m.lines;
    h.material = h.prim_id < l.material.size() ? l.material[h.prim_id] : 0;
    h.unlit = m.lines_unlit;
    const Key& k0 = m.keys[l.segments[h.prim_id]];
    const Key& k1 = m.keys[l.segments[h.prim_id] + 1];
    h.radius = k0[3] + (k1[3] - k0[3]) * rh.hit.u;
    float scale = std::fmax(std::fabs(h.position.x),
                            std::fmax(std::fabs(h.position.y), std::fabs(h.position.z)));
    // Measured (accel_test): with the leaving segment skipped, no offset is needed even at
    // joints; a small one guards against float error at large coordinates.
    h.spawn_offset = 1e-3f * h.radius + 1e-6f * scale;
    return h;
}

bool EmbreeScene::occluded(const Vec3f& org, const Vec3f& dir, float tnear, float tfar,
                           PrimId skip) const
{
    SkipContext context = make_context(skip, false);
    RTCRay r;
    r.org_x = org.x;
    r.org_y = org.y;
    r.org_z = org.z;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.tnear = tnear;
    r.tfar = tfar;
    r.time = 0;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(m_impl->scene, &context.context, &r);
    // Embree marks an occluded ray by setting tfar to -inf.
    return r.tfar < 0 && std::isinf(r.tfar);
}

}  // namespace cambium::render
