// ASCII OFF reader. Line-based, as OpenMesh's reader effectively was: after
// the keyword ([ST][C][N]OFF) and the counts line ("<vertices> <faces>
// [<edges>]", which may follow the keyword on its line), each vertex is a line
// whose first three numbers are x, y, z (normals, colours and texture
// coordinates after them are ignored), and each face a line "<n> <i1> .. <in>"
// followed by optional colour columns (ignored). '#' starts a comment
// anywhere; blank lines are skipped. 4OFF, nOFF and binary OFF are refused
// with a clear error. See mesh_readers.hpp for the promises every reader keeps.

#include "culling/errors.hpp"
#include "mesh_readers.hpp"

#include <cmath>
#include <limits>

namespace lc::meshio {

namespace {

// Content lines of the file: comments stripped, blank lines skipped, split
// into whitespace-separated tokens.
class Lines {
  public:
    explicit Lines(std::string_view bytes) : bytes_(bytes) {}

    // The next line with a token; false at the end of the file.
    bool next() {
        tokens.clear();
        while (pos_ < bytes_.size()) {
            std::size_t nl = bytes_.find('\n', pos_);
            if (nl == std::string_view::npos) nl = bytes_.size();
            text = bytes_.substr(pos_, nl - pos_);
            pos_ = nl < bytes_.size() ? nl + 1 : nl;
            ++line;
            const std::size_t hash = text.find('#');
            if (hash != std::string_view::npos) text = text.substr(0, hash);
            while (!text.empty() && isSpace(text.back()))
                text.remove_suffix(1);
            while (!text.empty() && isSpace(text.front()))
                text.remove_prefix(1);
            std::size_t i = 0;
            while (i < text.size()) {
                while (i < text.size() && isSpace(text[i]))
                    ++i;
                const std::size_t b = i;
                while (i < text.size() && !isSpace(text[i]))
                    ++i;
                if (i > b) tokens.push_back(text.substr(b, i - b));
            }
            if (!tokens.empty()) return true;
        }
        return false;
    }
    std::size_t offset() const { return pos_; }

    std::vector<std::string_view> tokens;
    std::string_view text; // the current line without its comment
    int line = 0;          // 1-based number of the current line

  private:
    static bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
    std::string_view bytes_;
    std::size_t pos_ = 0;
};

} // namespace

void readOff(std::string_view bytes, const ReadContext& ctx, FlatMesh& out) {
    const std::string& path = ctx.path;
    Lines in(bytes);
    if (!in.next())
        throw InputError(path, "", in.line, "OFF file: no OFF keyword (only blank or comment lines)");

    // The keyword: [ST][C][N][4][n]OFF.
    const std::string_view keyword = in.tokens[0];
    const std::size_t stem = keyword.size() >= 3 ? keyword.size() - 3 : 0;
    const std::string_view prefix = keyword.substr(0, stem);
    if (keyword.size() < 3 || keyword.substr(stem) != "OFF" ||
        prefix.find_first_not_of("STCN4n") != std::string_view::npos)
        throw InputError(path, "", in.line,
                         "OFF file: the first line must name the OFF format, not " + quoted(in.text));
    if (prefix.find_first_of("4n") != std::string_view::npos)
        throw InputError(path, "", in.line,
                         "OFF file: " + std::string(keyword) + " (4-D or n-D vertices) is not supported");
    std::vector<std::string_view> counts(in.tokens.begin() + 1, in.tokens.end());
    if (!counts.empty() && counts[0] == "BINARY")
        throw InputError(path, "", in.line, "OFF file: binary OFF is not supported; use ASCII OFF or PLY");
    if (counts.empty()) {
        if (!in.next()) throw InputError(path, "", in.line, "OFF file: no counts line");
        counts = in.tokens;
    }
    const int countsLine = in.line;
    std::int64_t c[3] = {0, 0, 0};
    bool countsOk = counts.size() == 2 || counts.size() == 3;
    for (std::size_t k = 0; countsOk && k < counts.size(); ++k)
        countsOk = parseInteger(counts[k], c[k]) && c[k] >= 0;
    if (!countsOk)
        throw InputError(path, "", countsLine,
                         "OFF file: the counts line is \"<vertices> <faces> <edges>\", not " +
                             quoted(in.text));
    const std::uint64_t nv = std::uint64_t(c[0]), nf = std::uint64_t(c[1]);
    if (nv == 0 || nf == 0)
        throw InputError(path, "", countsLine,
                         "OFF file announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                             " faces: no triangles");
    // Every vertex and face is a line of at least two bytes.
    const std::uint64_t size = bytes.size();
    if (nv > size / 2 + 1 || nf > size / 2 + 1)
        throw InputError(path, "", countsLine,
                         "OFF file announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                             " faces, more than the " + std::to_string(size) + "-byte file can hold");

    out.positions.reserve(std::size_t(nv) * 3);
    for (std::uint64_t v = 0; v < nv; ++v) {
        if ((v & 0xFFFF) == 0xFFFF) ctx.tick(in.offset(), bytes.size());
        if (!in.next())
            throw InputError(path, "", in.line,
                             "OFF file ends before vertex " + std::to_string(v) + " of " +
                                 std::to_string(nv));
        if (in.tokens.size() < 3)
            throw InputError(path, "", in.line,
                             "OFF file: vertex " + std::to_string(v) + " needs three coordinates, not " +
                                 quoted(in.text));
        for (int k = 0; k < 3; ++k) {
            float x = 0;
            if (!parseFloat(in.tokens[k], x))
                throw InputError(path, "", in.line,
                                 "OFF file: vertex " + std::to_string(v) + ": " + quoted(in.tokens[k]) +
                                     " is not a number");
            if (!std::isfinite(x))
                throw InputError(path, "", in.line,
                                 "vertex " + std::to_string(v) + " has a non-finite coordinate " +
                                     quoted(in.tokens[k]));
            out.positions.push_back(x);
        }
    }

    out.polyStart.reserve(std::size_t(nf));
    for (std::uint64_t f = 0; f < nf; ++f) {
        if ((f & 0xFFFF) == 0xFFFF) ctx.tick(in.offset(), bytes.size());
        if (!in.next())
            throw InputError(path, "", in.line,
                             "OFF file ends before face " + std::to_string(f) + " of " + std::to_string(nf));
        std::int64_t n = -1;
        if (!parseInteger(in.tokens[0], n) || n < 0)
            throw InputError(path, "", in.line,
                             "OFF file: face " + std::to_string(f) + " gives " + quoted(in.tokens[0]) +
                                 " as its vertex count; expected a whole number");
        // The line must hold the indices; what follows them is colour.
        if (std::uint64_t(n) > in.tokens.size() - 1)
            throw InputError(path, "", in.line,
                             "OFF file: face " + std::to_string(f) + " announces " + std::to_string(n) +
                                 " vertices but its line holds " + std::to_string(in.tokens.size() - 1) +
                                 " numbers after the count");
        if (out.polyIndices.size() > std::numeric_limits<std::uint32_t>::max())
            throw InputError(path, "", in.line, "OFF file: more than 2^32 face corners");
        out.polyStart.push_back(std::uint32_t(out.polyIndices.size()));
        for (std::int64_t k = 1; k <= n; ++k) {
            std::int64_t idx = 0;
            if (!parseInteger(in.tokens[std::size_t(k)], idx))
                throw InputError(path, "", in.line,
                                 "OFF file: face " + std::to_string(f) + ": " +
                                     quoted(in.tokens[std::size_t(k)]) + " is not a vertex index");
            if (idx < 0 || std::uint64_t(idx) >= nv)
                throw InputError(path, "", in.line,
                                 "face " + std::to_string(f) + " refers to vertex " + std::to_string(idx) +
                                     ", outside 0.." + std::to_string(nv - 1));
            out.polyIndices.push_back(idx);
        }
    }
    // Anything after the last face (OpenMesh ignored it too) is ignored.
}

} // namespace lc::meshio
