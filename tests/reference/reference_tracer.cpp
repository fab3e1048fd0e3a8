// The reference tracer: every solid here (ball, flat-ended cylinder, half-space) is convex, so a
// ray meets each in one interval [t0, t1]. Rays start outside every solid (checked), so the
// first point of a union the ray reaches is the smallest entry t0 of its parts, and a shadow
// segment is blocked exactly when some part's interval overlaps it.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "reference_tracer.h"

namespace reftrace {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

Vec operator+(const Vec& a, const Vec& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Vec operator-(const Vec& a, const Vec& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Vec operator*(Real s, const Vec& a) {
    return {s * a.x, s * a.y, s * a.z};
}
Real dot(const Vec& a, const Vec& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec cross(const Vec& a, const Vec& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec normalize(const Vec& a) {
    return (1 / std::sqrt(dot(a, a))) * a;
}
Vec mul(const Real m[3][3], const Vec& v) {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}
Vec mul_transposed(const Real m[3][3], const Vec& v) {
    return {m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z,
            m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
            m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z};
}

struct Ray {
    Vec o, d;  // d need not be of unit length: instances map it without renormalising
};

// Where a ray is inside a convex solid, and the outward normal at the entry t0.
struct Span {
    Real t0 = kInf, t1 = -kInf;
    Vec n;
    bool empty() const { return !(t0 <= t1); }
};

// Solutions of a t^2 + 2 b t + c <= 0 for a > 0, by the cancellation-free form.
bool quadratic_span(Real a, Real b, Real c, Real& t0, Real& t1) {
    const Real disc = b * b - a * c;
    if (disc < 0) return false;
    const Real q = -(b + std::copysign(std::sqrt(disc), b));
    if (q == 0) {
        t0 = t1 = 0;
        return true;
    }
    t0 = q / a;
    t1 = c / q;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

Span ball_span(const Ray& r, const Ball& b) {
    Span s;
    const Vec w = r.o - b.c;
    if (quadratic_span(dot(r.d, r.d), dot(w, r.d), dot(w, w) - b.r * b.r, s.t0, s.t1)) {
        s.n = r.o + s.t0 * r.d - b.c;
    }
    return s;
}

Span cylinder_span(const Ray& r, const Cylinder& c) {
    Span s;
    const Vec w = r.o - c.a;
    const Real wa = dot(w, c.axis), da = dot(r.d, c.axis);
    // The slab between the end planes, 0 <= s <= length along the axis.
    Real s0 = -kInf, s1 = kInf;
    if (da == 0) {
        if (wa < 0 || wa > c.length) return s;
    } else {
        s0 = -wa / da;
        s1 = (c.length - wa) / da;
        if (s0 > s1) std::swap(s0, s1);
    }
    // The infinite tube: the components across the axis.
    const Vec wp = w - wa * c.axis, dp = r.d - da * c.axis;
    Real l0 = -kInf, l1 = kInf;
    const Real a = dot(dp, dp);
    if (a == 0) {
        if (dot(wp, wp) > c.r * c.r) return s;
    } else if (!quadratic_span(a, dot(wp, dp), dot(wp, wp) - c.r * c.r, l0, l1)) {
        return s;
    }
    s.t0 = std::max(s0, l0);
    s.t1 = std::min(s1, l1);
    if (s.empty()) return s;
    if (l0 >= s0) {
        s.n = wp + l0 * dp;  // entered through the side
    } else {
        s.n = da > 0 ? -1 * c.axis : c.axis;  // through the end at s = 0 or s = length
    }
    return s;
}

Span halfspace_span(const Ray& r, const Object& o) {
    Span s;
    const Real wn = dot(r.o - o.point, o.normal), dn = dot(r.d, o.normal);
    if (dn == 0) {
        if (wn <= 0) s.t0 = -kInf, s.t1 = kInf;  // parallel: all inside or all outside
    } else if (dn < 0) {
        s.t0 = -wn / dn, s.t1 = kInf;
    } else {
        s.t0 = -kInf, s.t1 = -wn / dn;
    }
    s.n = o.normal;
    return s;
}

// Does the ray's [tmin, tmax] meet the box at all?
bool box_overlaps(const Ray& r, const Vec& lo, const Vec& hi, Real tmin, Real tmax) {
    const Real o[3] = {r.o.x, r.o.y, r.o.z}, d[3] = {r.d.x, r.d.y, r.d.z};
    const Real l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0) {
            if (o[k] < l[k] || o[k] > h[k]) return false;
            continue;
        }
        Real a = (l[k] - o[k]) / d[k], b = (h[k] - o[k]) / d[k];
        if (a > b) std::swap(a, b);
        tmin = std::max(tmin, a);
        tmax = std::min(tmax, b);
        if (tmin > tmax) return false;
    }
    return true;
}

// Calls f(span, component) for each part of object o that could matter on [tmin, tmax];
// instance spans come with t along the world ray and normals in primitive coordinates.
template <class F>
void for_each_span(const Scene& scene, const Object& o, const Ray& r, Real tmin, Real tmax, F&& f) {
    if (o.kind == Kind::sphere) {
        f(ball_span(r, o.ball), 0);
    } else if (o.kind == Kind::halfspace) {
        f(halfspace_span(r, o), 0);
    } else {
        if (!box_overlaps(r, o.lo, o.hi, tmin, tmax)) return;
        // Same t in both spaces: local = minv * (world - t), directions unnormalised.
        const Ray local{mul(o.minv, r.o - o.t), mul(o.minv, r.d)};
        const Primitive& p = scene.primitives[o.primitive];
        const int nb = static_cast<int>(p.balls.size());
        for (int k = 0; k < nb; ++k) f(ball_span(local, p.balls[k]), k);
        for (int k = 0; k < static_cast<int>(p.cylinders.size()); ++k) {
            f(cylinder_span(local, p.cylinders[k]), nb + k);
        }
    }
}

struct Hit {
    Real t = kInf;
    int object = -1, component = -1;
    Vec n;  // outward, unit, world
};

Hit closest_hit(const Scene& scene, const Ray& r) {
    Hit h;
    for (int k = 0; k < static_cast<int>(scene.objects.size()); ++k) {
        const Object& o = scene.objects[k];
        for_each_span(scene, o, r, 0, h.t, [&](const Span& s, int component) {
            if (s.empty() || !(s.t0 > 0) || !(s.t0 < h.t)) return;
            h.t = s.t0;
            h.object = k;
            h.component = component;
            // Normals of instances map by the inverse transpose.
            h.n = normalize(o.kind == Kind::instance ? mul_transposed(o.minv, s.n) : s.n);
        });
    }
    return h;
}

// Is there solid on the segment from p (excluding the first kShadowEpsilon) to the light?
bool blocked(const Scene& scene, const Vec& p, const Vec& light) {
    const Ray r{p, light - p};  // t = 1 at the light
    const Real tmin = kShadowEpsilon / std::sqrt(dot(r.d, r.d));
    bool found = false;
    for (const Object& o : scene.objects) {
        for_each_span(scene, o, r, tmin, 1, [&](const Span& s, int) {
            if (!s.empty() && s.t1 > tmin && s.t0 < 1) found = true;
        });
        if (found) return true;
    }
    return false;
}

Vec camera_ray(const Camera& cam, int width, int height, int i, int j) {
    const Vec w = normalize(cam.look_at - cam.eye);
    const Vec u = normalize(cross(w, cam.up));
    const Vec v = cross(u, w);
    const Real h = std::tan(cam.fov_y_deg * std::numbers::pi_v<Real> / 360);
    const Real a = static_cast<Real>(width) / height;
    const Real x = (2 * (i + 0.5L) / width - 1) * a * h;
    const Real y = (1 - 2 * (j + 0.5L) / height) * h;
    return normalize(w + x * u + y * v);
}

bool inside(const Scene& scene, const Vec& x) {
    // A point is inside a solid when a ray from it starts within that solid's interval.
    const Ray r{x, {0, 0, 1}};
    bool in = false;
    for (const Object& o : scene.objects) {
        for_each_span(scene, o, r, -kInf, kInf, [&](const Span& s, int) {
            if (!s.empty() && s.t0 <= 0 && s.t1 >= 0) in = true;
        });
    }
    return in;
}

PixelTrace trace(const Scene& scene, const Ray& ray) {
    PixelTrace out;
    out.light_seen = std::vector<char>(scene.lights.size(), 0);
    const Hit h = closest_hit(scene, ray);
    if (h.object < 0) {
        out.color = scene.background;
        return out;
    }
    out.hit = true;
    out.object = h.object;
    out.component = h.component;
    out.t = h.t;
    out.p = ray.o + h.t * ray.d;
    const Vec V = -1 * ray.d;
    out.n = dot(h.n, V) < 0 ? -1 * h.n : h.n;
    const Vec& N = out.n;
    const Material& m = scene.materials[scene.objects[h.object].material];
    const Vec& amb = scene.ambient;
    Vec c{m.ka * m.color.x * amb.x, m.ka * m.color.y * amb.y, m.ka * m.color.z * amb.z};
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
        const Light& light = scene.lights[l];
        if (scene.shadows && blocked(scene, out.p, light.position)) continue;
        out.light_seen[l] = 1;
        const Vec L = normalize(light.position - out.p);
        const Real nl = dot(N, L);
        const Vec R = 2 * nl * N - L;
        // As the README writes it: no N.L > 0 condition on the specular term.
        const Real spec = m.ks * std::pow(std::max<Real>(0, dot(R, V)), m.shininess);
        const Real diff = m.kd * std::max<Real>(0, nl);
        c = c + Vec{light.intensity.x * (diff * m.color.x + spec),
                    light.intensity.y * (diff * m.color.y + spec),
                    light.intensity.z * (diff * m.color.z + spec)};
    }
    out.color = c;
    return out;
}

std::uint8_t to_byte(Real c) {
    return static_cast<std::uint8_t>(std::lround(255 * std::clamp<Real>(c, 0, 1)));
}

// Pixels [x0, x0 + w) x [y0, y0 + h) of the view rendered at width x height.
Image render_pixels(const Scene& scene, int width, int height, int x0, int y0, int w, int h,
                    int threads) {
    if (w < 0 || h < 0 || x0 < 0 || y0 < 0 || x0 + w > width || y0 + h > height) {
        throw std::invalid_argument("reference window outside the image");
    }
    if (inside(scene, scene.camera.eye)) {
        throw std::runtime_error("the eye is inside a solid; the reference tracer assumes not");
    }
    Image img{w, h, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(w) * h)};
    std::atomic<int> next_row{0};
    auto work = [&] {
        for (int row = next_row++; row < h; row = next_row++) {
            for (int col = 0; col < w; ++col) {
                const Ray ray{scene.camera.eye,
                              camera_ray(scene.camera, width, height, x0 + col, y0 + row)};
                const Vec c = trace(scene, ray).color;
                std::uint8_t* px = &img.rgb[3 * (static_cast<std::size_t>(row) * w + col)];
                px[0] = to_byte(c.x);
                px[1] = to_byte(c.y);
                px[2] = to_byte(c.z);
            }
        }
    };
    if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int k = 1; k < threads; ++k) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    return img;
}

}  // namespace

Image render(const Scene& scene, int threads) {
    const Camera& c = scene.camera;
    return render_pixels(scene, c.width, c.height, 0, 0, c.width, c.height, threads);
}

Image render_resized(const Scene& scene, int w, int h, int threads) {
    if (w <= 0 || h <= 0) throw std::invalid_argument("reference image size must be positive");
    return render_pixels(scene, w, h, 0, 0, w, h, threads);
}

Image render_window(const Scene& scene, int x0, int y0, int w, int h, int threads) {
    const Camera& c = scene.camera;
    return render_pixels(scene, c.width, c.height, x0, y0, w, h, threads);
}

PixelTrace trace_pixel(const Scene& scene, int width, int height, int i, int j) {
    return trace(scene, Ray{scene.camera.eye, camera_ray(scene.camera, width, height, i, j)});
}

}  // namespace reftrace
