// Built-in procedural scenes: the project's own geometry, generated in code
// and deterministic (no files, no std random distributions). All distances are
// in world units ("metres"); world is right-handed, Y up.

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <cmath>

namespace lc {

namespace {

constexpr double kPi = 3.14159265358979323846;

// splitmix64 for placement jitter (the same generator as light_gen.cpp).
struct Rng {
    std::uint64_t state;
    double unit() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    }
    double range(double lo, double hi) { return lo + (hi - lo) * unit(); }
};

// Accumulates triangles into one world-space mesh (transform = identity).
struct Builder {
    Mesh mesh;
    explicit Builder(std::string name) { mesh.name = std::move(name); }

    std::uint32_t vertex(glm::dvec3 p) {
        mesh.positions.insert(mesh.positions.end(), {float(p.x), float(p.y), float(p.z)});
        return std::uint32_t(mesh.positions.size() / 3 - 1);
    }
    void tri(std::uint32_t a, std::uint32_t b, std::uint32_t c) { mesh.indices.insert(mesh.indices.end(), {a, b, c}); }
    void quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
        const auto ia = vertex(a), ib = vertex(b), ic = vertex(c), id = vertex(d);
        tri(ia, ib, ic);
        tri(ia, ic, id);
    }
    // Axis-aligned box, 12 triangles.
    void box(glm::dvec3 lo, glm::dvec3 hi) {
        const glm::dvec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                                 {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
        quad(p[0], p[3], p[2], p[1]); // -z
        quad(p[4], p[5], p[6], p[7]); // +z
        quad(p[0], p[4], p[7], p[3]); // -x
        quad(p[1], p[2], p[6], p[5]); // +x
        quad(p[0], p[1], p[5], p[4]); // -y
        quad(p[3], p[7], p[6], p[2]); // +y
    }
    // Vertical cylinder or cone frustum around `base`, with caps: a closed
    // solid wound counter-clockwise seen from outside, as every closed shape
    // here (the depth pre-pass leaves out faces turned away from the camera).
    void cylinder(glm::dvec3 base, double r0, double r1, double h, int seg) {
        const std::uint32_t first = std::uint32_t(mesh.positions.size() / 3);
        for (int i = 0; i < seg; ++i) {
            const double a = 2 * kPi * i / seg;
            vertex(base + glm::dvec3(r0 * std::cos(a), 0, r0 * std::sin(a)));
            vertex(base + glm::dvec3(r1 * std::cos(a), h, r1 * std::sin(a)));
        }
        const auto bc = vertex(base), tc = vertex(base + glm::dvec3(0, h, 0));
        for (int i = 0; i < seg; ++i) {
            const std::uint32_t j = (i + 1) % seg;
            const std::uint32_t b0 = first + 2 * i, t0 = b0 + 1, b1 = first + 2 * j, t1 = b1 + 1;
            tri(b0, t0, t1);
            tri(b0, t1, b1);
            tri(bc, b0, b1);
            if (r1 > 0) tri(tc, t1, t0);
        }
    }
    void sphere(glm::dvec3 c, double r, int rings, int seg) {
        const std::uint32_t first = std::uint32_t(mesh.positions.size() / 3);
        for (int i = 0; i <= rings; ++i) {
            const double th = kPi * i / rings;
            // The poles exactly on the axis (sin(pi) is not 0 in double), so
            // that each pole's ring is one position and the sphere is closed.
            const double sinTh = i == 0 || i == rings ? 0.0 : std::sin(th), cosTh = std::cos(th);
            for (int j = 0; j < seg; ++j) {
                const double ph = 2 * kPi * j / seg;
                vertex(c + r * glm::dvec3(sinTh * std::cos(ph), cosTh, sinTh * std::sin(ph)));
            }
        }
        for (int i = 0; i < rings; ++i)
            for (int j = 0; j < seg; ++j) {
                const std::uint32_t a = first + i * seg + j, b = first + i * seg + (j + 1) % seg;
                const std::uint32_t c2 = a + seg, d = b + seg;
                if (i > 0) tri(a, b, d);          // the poles' rows collapse to a point
                if (i + 1 < rings) tri(a, d, c2);
            }
    }
    // Semicircular arch in the XY plane (extruded along z by `depth`), from
    // centre `c`, inner radius r, thickness t, made of `seg` box-like pieces.
    void arch(glm::dvec3 c, double r, double t, double depth, int seg) {
        for (int i = 0; i < seg; ++i) {
            const double a0 = kPi * i / seg, a1 = kPi * (i + 1) / seg;
            auto at = [&](double a, double rr, double z) {
                return c + glm::dvec3(rr * std::cos(a), rr * std::sin(a), z);
            };
            const double z0 = -depth / 2, z1 = depth / 2, R = r + t;
            quad(at(a0, r, z0), at(a1, r, z0), at(a1, R, z0), at(a0, R, z0));  // front
            quad(at(a0, r, z1), at(a0, R, z1), at(a1, R, z1), at(a1, r, z1));  // back
            quad(at(a0, r, z0), at(a0, r, z1), at(a1, r, z1), at(a1, r, z0));  // intrados
            quad(at(a0, R, z0), at(a1, R, z0), at(a1, R, z1), at(a0, R, z1));  // extrados
        }
    }
    // Heightfield over [x0,x1] x [z0,z1] with n x n cells.
    template <class F> void heightfield(double x0, double x1, double z0, double z1, int n, F height) {
        const std::uint32_t first = std::uint32_t(mesh.positions.size() / 3);
        for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n; ++j) {
                const double x = x0 + (x1 - x0) * j / n, z = z0 + (z1 - z0) * i / n;
                vertex({x, height(x, z), z});
            }
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const std::uint32_t a = first + i * (n + 1) + j, b = a + 1, c = a + (n + 1), d = c + 1;
                tri(a, c, d);
                tri(a, d, b);
            }
    }
};

Camera perspectiveCamera(glm::dvec3 pos, glm::dvec3 target, double fov, double nearP, double farP) {
    Camera c;
    c.position = pos;
    c.target = target;
    c.up = {0, 1, 0};
    c.projection = ProjectionKind::Perspective;
    c.fovYDeg = fov;
    c.nearPlane = nearP;
    c.farPlane = farP;
    c.width = 1280;
    c.height = 720;
    c.tileSize = 16;
    return c;
}

// Lights in a given volume with intensities chosen so that radii
// r = sqrt(I * max(c) / I_min) lie between about rMin and rMax.
std::vector<PointLight> lightsIn(glm::dvec3 lo, glm::dvec3 hi, std::uint32_t count, double rMin, double rMax,
                                 std::uint64_t seed) {
    LightGenSettings g;
    g.count = count;
    g.seed = seed;
    g.boxMin = lo;
    g.boxMax = hi;
    g.minIntensity = 0.05;
    g.colorMin = glm::dvec3(0.3);
    g.colorMax = glm::dvec3(1.0);
    // With max(c) in [0.3,1]: r^2 = I*max(c)/I_min; pick I so r spans ~[rMin,rMax].
    g.intensityMin = rMin * rMin * g.minIntensity;
    g.intensityMax = rMax * rMax * g.minIntensity;
    return generateLights(g);
}

Scene forest() {
    Scene s;
    s.name = "forest";
    Builder b("forest");
    b.quad({-150, 0, -250}, {-150, 0, 50}, {150, 0, 50}, {150, 0, -250});  // far-reaching ground
    Rng rng{42};
    for (int i = 0; i < 400; ++i) {
        const glm::dvec3 base(rng.range(-60, 60), 0, rng.range(-200, 20));
        const double h = rng.range(8, 18), r = rng.range(0.12, 0.35);
        b.cylinder(base, r, r * 0.6, h, 8);                                    // trunk
        b.cylinder(base + glm::dvec3(0, h * 0.55, 0), r * 8, 0, h * 0.6, 10);  // crown
        for (int k = 0; k < 6; ++k) {  // grass blades: thin vertical sheets
            const glm::dvec3 g(base.x + rng.range(-3, 3), 0, base.z + rng.range(-3, 3));
            const double w = 0.04, gh = rng.range(0.5, 1.5);
            b.quad(g + glm::dvec3(-w, 0, 0), g + glm::dvec3(w, 0, 0), g + glm::dvec3(w * 0.2, gh, 0),
                   g + glm::dvec3(-w * 0.2, gh, 0));
        }
    }
    s.meshes.push_back(std::move(b.mesh));
    s.camera = perspectiveCamera({0, 1.7, 30}, {0, 4, 0}, 60, 0.1, 500);
    s.lights = lightsIn({-60, 0.2, -200}, {60, 12, 30}, 384, 3, 9, 1);
    return s;
}

Scene mountain() {
    Scene s;
    s.name = "mountain";
    Builder terrain("terrain");
    // Distant ridges: heights up to ~120 m, 150..650 m from the camera.
    terrain.heightfield(-500, 500, -650, -100, 160, [](double x, double z) {
        const double d = (-z - 100) / 550;  // 0 near, 1 far
        return d * (60 + 40 * std::sin(x * 0.013) + 25 * std::sin(x * 0.041 + z * 0.017) +
                    10 * std::cos(z * 0.07 + x * 0.02));
    });
    Builder figure("figure");
    // A standing figure ~2 m tall, 6 m in front of the camera.
    figure.box({-0.35, 0, -0.2}, {0.35, 1.3, 0.2});        // body
    figure.sphere({0, 1.55, 0}, 0.22, 16, 24);              // head
    figure.box({-0.6, 0.7, -0.1}, {-0.38, 1.3, 0.1});      // arms
    figure.box({0.38, 0.7, -0.1}, {0.6, 1.3, 0.1});
    figure.quad({-5, 0, -5}, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}); // the ledge it stands on
    s.meshes.push_back(std::move(terrain.mesh));
    s.meshes.push_back(std::move(figure.mesh));
    s.camera = perspectiveCamera({0, 1.6, 6}, {0, 1.2, 0}, 50, 0.1, 1000);
    // Lights around the figure and scattered over the terrain.
    auto near = lightsIn({-4, 0.2, -4}, {4, 3, 4}, 64, 1, 3, 2);
    auto far = lightsIn({-400, 0, -600}, {400, 120, -120}, 192, 20, 60, 3);
    for (std::size_t i = 0; i < far.size(); ++i) far[i].name = "light_" + std::to_string(near.size() + i);
    s.lights = std::move(near);
    s.lights.insert(s.lights.end(), far.begin(), far.end());
    return s;
}

Scene atrium() {
    Scene s;
    s.name = "atrium";
    Builder b("atrium");
    const int kColumns = 12;
    const double spacing = 5, halfWidth = 6, floorH = 6;
    const double zEnd = -(kColumns - 1) * spacing;
    for (int f = 0; f < 3; ++f) {
        const double y = f * floorH;
        // Floors: full at ground level, galleries (open in the middle) above.
        if (f == 0) {
            b.box({-12, -0.3, zEnd - 6}, {12, 0, 6});
        } else {
            b.box({-12, y - 0.3, zEnd - 6}, {-halfWidth + 0.5, y, 6});
            b.box({halfWidth - 0.5, y - 0.3, zEnd - 6}, {12, y, 6});
        }
        for (int side = -1; side <= 1; side += 2) {
            const double x = side * halfWidth;
            for (int i = 0; i < kColumns; ++i) {
                const double z = -i * spacing;
                b.cylinder({x, y, z}, 0.4, 0.35, floorH - 1.6, 16);
                b.box({x - 0.5, y + floorH - 1.6, z - 0.5}, {x + 0.5, y + floorH - 1.3, z + 0.5});  // capital
            }
            // Arches between neighbouring columns, springing from the capitals.
            for (int i = 0; i + 1 < kColumns; ++i) {
                const double zc = -(i + 0.5) * spacing;
                Builder a("arch");
                a.arch({0, 0, 0}, spacing / 2 - 0.5, 0.4, 0.8, 12);
                // The arch is built in XY; swap x and z to stand it in the
                // colonnade's ZY plane, springing from the capitals' tops.
                const auto off = std::uint32_t(b.mesh.positions.size() / 3);
                for (std::size_t k = 0; k < a.mesh.positions.size(); k += 3)
                    b.vertex({x + a.mesh.positions[k + 2], y + floorH - 1.3 + a.mesh.positions[k + 1],
                              zc + a.mesh.positions[k]});
                for (std::uint32_t idx : a.mesh.indices) b.mesh.indices.push_back(off + idx);
            }
        }
    }
    b.box({-12.5, 0, zEnd - 6.5}, {12.5, 18, zEnd - 6}); // back wall
    s.meshes.push_back(std::move(b.mesh));
    s.camera = perspectiveCamera({0, 3, 12}, {0, 5, -20}, 60, 0.1, 200);
    s.lights = lightsIn({-11, 0.3, zEnd - 5}, {11, 17, 5}, 512, 1.5, 5, 4);
    return s;
}

// A flat wall perpendicular to the view axis. The camera looks straight down
// -Z at the plane z = 0 from z = 10, so every point of the wall has view depth
// -z_view = 10 exactly: each tile's min view depth equals its max. The wall
// spans 60 x 40 units, beyond the view's half-extents at distance 10
// (half-height 10*tan(30 deg) = 5.77, half-width 5.77*16/9 = 10.26).
Scene wall() {
    Scene s;
    s.name = "wall";
    Builder b("wall");
    const int n = 32;
    b.heightfield(-30, 30, -20, 20, n, [](double, double) { return 0.0; });
    // The heightfield lies in y = 0 (x, z); turn it into the plane z = 0 (x, y).
    for (std::size_t k = 0; k < b.mesh.positions.size(); k += 3) {
        const float y = b.mesh.positions[k + 1], z = b.mesh.positions[k + 2];
        b.mesh.positions[k + 1] = z;
        b.mesh.positions[k + 2] = y;
    }
    s.meshes.push_back(std::move(b.mesh));
    s.camera = perspectiveCamera({0, 0, 10}, {0, 0, 0}, 60, 0.1, 100);
    s.lights = lightsIn({-11, -6, -2}, {11, 6, 3}, 256, 1, 4, 5);
    return s;
}

// Mostly empty screen: one small object and a thin strip of distant ground
// at the horizon; most tiles hold no geometry at all.
Scene sky() {
    Scene s;
    s.name = "sky";
    Builder b("sky");
    b.sphere({8, 12, -40}, 2, 16, 32);            // a balloon in the upper right
    b.quad({-400, -30, -900}, {-400, -30, -600}, {400, -30, -600}, {400, -30, -900});  // horizon strip
    s.meshes.push_back(std::move(b.mesh));
    s.camera = perspectiveCamera({0, 0, 0}, {0, 5, -40}, 60, 0.1, 1000);
    s.lights = lightsIn({-30, -30, -100}, {30, 40, -10}, 64, 3, 10, 6);
    return s;
}

struct Entry {
    BuiltinInfo info;
    Scene (*make)();
};

const std::vector<Entry>& entries() {
    static const std::vector<Entry> e = {
        {{"atrium", "The default: a three-storey colonnade (24 columns per floor, arches, galleries) "
                    "with 512 lights of radius 1.5-5 m."},
         atrium},
        {{"forest", "400 thin trees with crowns and grass blades against a ground plane reaching 250 m "
                    "away: strong depth discontinuities in almost every tile. 384 lights."},
         forest},
        {{"mountain", "A 2 m figure on a ledge 6 m in front of the camera, framed against terrain "
                      "100-650 m away: near and far depth in the same tiles. 256 lights."},
         mountain},
        {{"wall", "A flat wall perpendicular to the view axis filling the screen: every pixel has view "
                  "depth exactly 10, so each tile's min equals its max. 256 lights."},
         wall},
        {{"sky", "Mostly empty screen: a small sphere and a thin horizon strip; most tiles hold no "
                 "geometry and must get empty lists. 64 lights."},
         sky},
    };
    return e;
}

} // namespace

const std::vector<BuiltinInfo>& builtinScenes() {
    static const std::vector<BuiltinInfo> infos = [] {
        std::vector<BuiltinInfo> v;
        for (const auto& e : entries()) v.push_back(e.info);
        return v;
    }();
    return infos;
}

Scene makeBuiltinScene(const std::string& name) {
    for (const auto& e : entries())
        if (e.info.name == name) {
            Scene s = e.make();
            s.origin.builtin = name;
            return s;
        }
    std::string list;
    for (const auto& e : entries()) list += (list.empty() ? "" : ", ") + e.info.name;
    throw SettingsError("builtin", "unknown built-in scene '" + name + "' (valid: " + list + ")");
}

} // namespace lc
