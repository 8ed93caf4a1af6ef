#include "scene/closed_solids.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace lc {

namespace {

// Per vertex index: the first index at the same position (bitwise, -0 as +0).
// Readers split vertices along seams (glTF primitives with normals or
// texture coordinates); the solids are found on the welded positions.
std::vector<std::uint32_t> weldedVertices(const Mesh& m) {
    struct Key {
        std::uint32_t x, y, z;
        bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
    };
    struct KeyHash {
        std::size_t operator()(const Key& k) const {
            std::uint64_t h = (std::uint64_t(k.x) << 32 | k.y) * 0x9E3779B97F4A7C15ull;
            h ^= (h >> 29) ^ std::uint64_t(k.z) * 0xBF58476D1CE4E5B9ull;
            return std::size_t(h ^ (h >> 32));
        }
    };
    auto bits = [](float f) {
        if (f == 0.0f) f = 0.0f;
        std::uint32_t u;
        std::memcpy(&u, &f, 4);
        return u;
    };
    const std::size_t n = m.vertexCount();
    std::unordered_map<Key, std::uint32_t, KeyHash> first;
    first.reserve(n);
    std::vector<std::uint32_t> canon(n);
    for (std::size_t i = 0; i < n; ++i)
        canon[i] = first
                       .emplace(Key{bits(m.positions[3 * i]), bits(m.positions[3 * i + 1]),
                                    bits(m.positions[3 * i + 2])},
                                std::uint32_t(i))
                       .first->second;
    return canon;
}

struct DisjointSets {
    std::vector<std::uint32_t> parent;
    explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    }
    void join(std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
};

glm::dvec3 corner(const Mesh& m, std::size_t t, int k) {
    return glm::dvec3(m.vertex(m.indices[3 * t + k]));
}

} // namespace

ClosedSolids findClosedSolids(const Mesh& mesh) {
    const std::size_t T = mesh.triangleCount();
    ClosedSolids s;
    s.solidOf.assign(T, -1);
    s.planes.assign(T, glm::dvec4(0.0));
    if (T == 0 || mesh.vertexCount() == 0) return s;
    const std::vector<std::uint32_t> canon = weldedVertices(mesh);

    // The directed edges (a, b) as a << 32 | b, of every triangle with three
    // distinct (welded) corners; the others cannot be part of a solid.
    struct Edge {
        std::uint64_t key;
        std::uint32_t tri;
        bool operator<(const Edge& o) const { return key != o.key ? key < o.key : tri < o.tri; }
    };
    std::vector<Edge> edges;
    edges.reserve(3 * T);
    std::vector<char> open(T, 0);
    const std::size_t vertices = canon.size();
    for (std::size_t t = 0; t < T; ++t) {
        const std::uint32_t* i = &mesh.indices[3 * t];
        if (i[0] >= vertices || i[1] >= vertices || i[2] >= vertices) { // Mesh::validate() says what is wrong
            open[t] = 1;
            continue;
        }
        const std::uint32_t v[3] = {canon[i[0]], canon[i[1]], canon[i[2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            open[t] = 1;
            continue;
        }
        for (int k = 0; k < 3; ++k)
            edges.push_back({std::uint64_t(v[k]) << 32 | v[(k + 1) % 3], std::uint32_t(t)});
    }
    std::sort(edges.begin(), edges.end());

    // Triangles join across an edge met once in each direction; an edge met
    // otherwise (a border, a third triangle, two in one direction) opens the
    // triangles that have it, and so their whole part.
    DisjointSets parts(T);
    auto keyLess = [](const Edge& e, std::uint64_t k) { return e.key < k; };
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i;
        while (j < edges.size() && edges[j].key == edges[i].key)
            ++j;
        const std::uint64_t reverse = edges[i].key << 32 | edges[i].key >> 32;
        const auto lo = std::lower_bound(edges.begin(), edges.end(), reverse, keyLess);
        const bool once =
            lo != edges.end() && lo->key == reverse && (lo + 1 == edges.end() || lo[1].key != reverse);
        if (j - i == 1 && once)
            parts.join(edges[i].tri, lo->tri);
        else
            for (std::size_t k = i; k < j; ++k)
                open[edges[k].tri] = 1;
        i = j;
    }

    // Per closed part: its box and six times its signed volume (about one of
    // its corners, for precision far from the origin).
    struct Part {
        bool open = false;
        glm::dvec3 origin{0.0}, lo{std::numeric_limits<double>::infinity()},
            hi{-std::numeric_limits<double>::infinity()};
        double volume6 = 0;
        bool seen = false;
        std::int32_t solid = -1;
    };
    std::unordered_map<std::uint32_t, Part> byRoot;
    std::vector<std::uint32_t> root(T);
    for (std::size_t t = 0; t < T; ++t) {
        root[t] = parts.find(std::uint32_t(t));
        Part& p = byRoot[root[t]];
        if (open[t]) p.open = true;
        if (p.open) continue;
        const glm::dvec3 a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
        if (!p.seen) p.origin = a, p.seen = true;
        p.lo = glm::min(p.lo, glm::min(a, glm::min(b, c)));
        p.hi = glm::max(p.hi, glm::max(a, glm::max(b, c)));
        p.volume6 += glm::dot(a - p.origin, glm::cross(b - p.origin, c - p.origin));
    }
    for (std::size_t t = 0; t < T; ++t) {
        Part& p = byRoot[root[t]];
        if (p.open) continue;
        // A part that encloses (next to) no volume, such as a sheet and its
        // reverse sharing vertices, has no outside to speak of: open.
        const double size = glm::length(p.hi - p.lo);
        if (!(std::abs(p.volume6) > 1e-9 * size * size * size)) {
            p.open = true;
            continue;
        }
        if (p.solid < 0) {
            p.solid = std::int32_t(s.lo.size());
            s.lo.push_back(p.lo);
            s.hi.push_back(p.hi);
        }
        const glm::dvec3 a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
        const glm::dvec3 n = (p.volume6 > 0 ? 1.0 : -1.0) * glm::cross(b - a, c - a);
        s.solidOf[t] = p.solid;
        s.planes[t] = glm::dvec4(n, glm::dot(n, a));
    }
    return s;
}

std::size_t appendDepthTriangles(const Mesh& mesh, const ClosedSolids& solids,
                                 const glm::dmat4& viewFromModel, const Projection& proj,
                                 std::vector<std::uint32_t>& out) {
    const std::size_t T = mesh.triangleCount();
    auto everything = [&] {
        out.insert(out.end(), mesh.indices.begin(), mesh.indices.begin() + std::ptrdiff_t(3 * T));
        return T;
    };
    const glm::dmat4& M = viewFromModel;
    // glm is column-major: M[c][3] is the bottom row.
    if (solids.solidCount() == 0 || solids.solidOf.size() != T || M[0][3] != 0.0 || M[1][3] != 0.0 ||
        M[2][3] != 0.0 || M[3][3] != 1.0)
        return everything();
    const double det = glm::determinant(glm::dmat3(M));
    if (!std::isfinite(det) || det == 0.0) return everything();
    const glm::dmat4 modelFromView = glm::inverse(M);
    const bool ortho = proj.orthographic();
    const glm::dvec3 eye(modelFromView * glm::dvec4(0, 0, 0, 1));
    const glm::dvec3 forward(modelFromView * glm::dvec4(0, 0, -1, 0));

    // A solid's faces are left out only where it lies wholly beyond the near
    // plane, by a margin over the float rasteriser's clipping: then the eye
    // (perspective) or the near plane (orthographic) is outside it, and every
    // view ray meets it first on a face turned towards the ray's origin.
    const double nearPlane = proj.nearPlane();
    std::vector<char> culled(solids.solidCount());
    for (std::size_t s = 0; s < solids.solidCount(); ++s) {
        double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 c((k & 1) ? solids.hi[s].x : solids.lo[s].x,
                               (k & 2) ? solids.hi[s].y : solids.lo[s].y,
                               (k & 4) ? solids.hi[s].z : solids.lo[s].z);
            const double d = -(M * glm::dvec4(c, 1.0)).z;
            dMin = std::min(dMin, d);
            dMax = std::max(dMax, d);
        }
        const double margin = 1e-4 * (std::abs(nearPlane) + (dMax - dMin));
        culled[s] = dMin > nearPlane + margin;
    }

    // Runs of triangles of one solid (or open): a run drawn whole is one copy.
    std::size_t drawn = 0;
    for (std::size_t t = 0; t < T;) {
        const std::int32_t s = solids.solidOf[t];
        std::size_t end = t + 1;
        while (end < T && solids.solidOf[end] == s) ++end;
        const auto first = mesh.indices.begin();
        if (s < 0 || !culled[std::size_t(s)]) {
            out.insert(out.end(), first + std::ptrdiff_t(3 * t), first + std::ptrdiff_t(3 * end));
            drawn += end - t;
        } else {
            for (std::size_t u = t; u < end; ++u) {
                const glm::dvec4& p = solids.planes[u];
                const glm::dvec3 n(p);
                const double towards = ortho ? -glm::dot(n, forward) : glm::dot(n, eye) - p.w;
                if (!(towards > 0)) continue;
                out.insert(out.end(), first + std::ptrdiff_t(3 * u), first + std::ptrdiff_t(3 * u + 3));
                ++drawn;
            }
        }
        t = end;
    }
    return drawn;
}

} // namespace lc
