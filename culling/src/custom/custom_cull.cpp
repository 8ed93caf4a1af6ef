// Custom culling, the parts without Vulkan: the layout and list-rule specs, a
// shader's first-line settings, decoding lists from raw words or CSV, locating
// false negatives, reading an engine's depth buffer, and the pipelines that
// judge a shader's or an engine's lists (docs/CUSTOM_CULLING.md).
#include "culling/custom/custom_cull.hpp"

#include "culling/core/errors.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/core/pipeline.hpp"
#include "custom/custom_internal.hpp"
#include "truth/light_grid.hpp"

#include <png.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

namespace lc {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> splitOn(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == sep) {
            out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    out.push_back(cur);
    return out;
}

bool parseUint(const std::string& s, std::uint64_t& v) {
    if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    v = std::stoull(s);
    return true;
}

// The built-in algorithm whose list rule a ListSpec names.
Algorithm ruleAlgorithm(const ListSpec& l) {
    switch (l.kind) {
    case ListKind::Tile: return Algorithm::MinMax;
    case ListKind::HalfZ: return Algorithm::HalfZ;
    case ListKind::Froxel: return Algorithm::Clustered;
    case ListKind::Cells: return Algorithm::TwoPointFiveD;
    }
    return Algorithm::MinMax;
}

// Sorted, unique, valid lists into `result`.
void assignLists(std::vector<std::vector<std::uint32_t>>& lists, std::uint32_t lightCount, CullResult& result,
                 CustomCullReport& report) {
    result.listOffset.assign(lists.size(), 0);
    result.listCount.assign(lists.size(), 0);
    result.lightIndices.clear();
    for (std::size_t l = 0; l < lists.size(); ++l) {
        auto& v = lists[l];
        const auto bad = std::remove_if(v.begin(), v.end(), [&](std::uint32_t i) { return i >= lightCount; });
        report.invalidIndices += std::uint64_t(v.end() - bad);
        if (bad != v.end()) report.invalidIndexListIds.push_back(std::uint32_t(l));
        v.erase(bad, v.end());
        std::sort(v.begin(), v.end());
        const auto dup = std::unique(v.begin(), v.end());
        report.duplicateIndices += std::uint64_t(v.end() - dup);
        if (dup != v.end()) report.duplicateIndexListIds.push_back(std::uint32_t(l));
        v.erase(dup, v.end());
        result.listOffset[l] = std::uint32_t(result.lightIndices.size());
        result.listCount[l] = std::uint32_t(v.size());
        result.lightIndices.insert(result.lightIndices.end(), v.begin(), v.end());
    }
}

} // namespace

namespace detail {

std::string readWholeFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", 0, "cannot open file for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

CullResult ruleSkeleton(const DepthImage& depth, const Projection& proj, const TileGrid& grid, const ViewLights& lights,
                        const ListSpec& lists) {
    CullSettings s;
    s.algorithm = ruleAlgorithm(lists);
    s.cells = lists.kind == ListKind::Froxel || lists.kind == ListKind::Cells ? lists.slices : 1;
    s.slicing = lists.slicing;
    s.skipEmpty = false; // a custom froxel list may hold lights in empty froxels
    if (const std::string bad = s.validate(); !bad.empty()) throw SettingsError("lists", bad);
    CullResult r = makeCpuBackend()->cull(depth, proj, grid, lights, s);
    if (lists.kind == ListKind::Cells) {
        // 2.5d's tile bounds and cell masks, with a list per cell; no
        // built-in algorithm makes such lists, so none to compare with.
        r.cellLists = true;
        r.listsPerTile = lists.slices;
        r.listOffset.assign(std::size_t(grid.tileCount()) * lists.slices, 0);
        r.listCount.assign(r.listOffset.size(), 0);
        r.lightIndices.clear();
    }
    return r;
}

void compareWithBuiltin(const CullResult& custom, const CullResult& builtin, CustomCullReport& report) {
    if (builtin.cellLists) {
        report.builtinAlgorithm = "none (no built-in algorithm has a list per cell)";
        return;
    }
    // Froxel lists: the built-in is clustered without skipping empty froxels
    // (ruleSkeleton); an engine that skips them (as `clustered` does by
    // default) is compared with those lists emptied where no pixel lies,
    // whichever of the two its lists are nearer.
    const bool froxels = builtin.algorithm == Algorithm::Clustered && !builtin.cellMask.empty();
    const std::uint32_t per = std::max(builtin.listsPerTile, 1u);
    std::uint64_t differ[2] = {0, 0}, entries[2] = {0, 0};
    for (std::size_t l = 0; l < builtin.listCount.size(); ++l) {
        const bool occupied = !froxels || (builtin.cellMask[l / per] >> (l % per) & 1u);
        const std::uint32_t n = builtin.listCount[l];
        const bool customHas = l < custom.listCount.size();
        const std::uint32_t m = customHas ? custom.listCount[l] : 0;
        const auto a = custom.lightIndices.begin() + (customHas ? custom.listOffset[l] : 0);
        const auto b = builtin.lightIndices.begin() + builtin.listOffset[l];
        const bool same = customHas && m == n && std::equal(a, a + m, b);
        differ[0] += !same;
        entries[0] += n;
        differ[1] += occupied ? !same : m != 0;
        entries[1] += occupied ? n : 0;
    }
    const int k = froxels && differ[1] < differ[0] ? 1 : 0;
    report.builtinAlgorithm = std::string(toString(builtin.algorithm)) + (!froxels ? "" : k ? ", skip-empty true" : ", skip-empty false");
    report.builtinEntries = entries[k];
    report.listsDifferingFromBuiltin = differ[k];
}

} // namespace detail

using detail::compareWithBuiltin;
using detail::ruleSkeleton;

LayoutSpec parseLayout(const std::string& text) {
    const auto parts = splitOn(text, ':');
    LayoutSpec l;
    std::uint64_t n = 0;
    if (parts[0] == "fixed" && parts.size() == 2 && parseUint(parts[1], n) && n >= 1 && n <= 65536) {
        l.kind = ListLayout::Fixed;
        l.capacity = std::uint32_t(n);
    } else if (parts[0] == "compact" && parts.size() == 1) {
        l.kind = ListLayout::Compact;
        l.capacity = 0;
    } else if (parts[0] == "compact" && parts.size() == 2 && parseUint(parts[1], n) && n >= 1 && n <= (1u << 28)) {
        l.kind = ListLayout::Compact;
        l.capacity = std::uint32_t(n);
    } else if (parts[0] == "bitmask" && parts.size() == 1) {
        l.kind = ListLayout::Bitmask;
        l.capacity = 0;
    } else {
        throw SettingsError("layout", "'" + text + "' is not fixed:N (N in 1..65536), compact, compact:N or bitmask");
    }
    return l;
}

std::string toString(const LayoutSpec& l) {
    switch (l.kind) {
    case ListLayout::Fixed: return "fixed:" + std::to_string(l.capacity);
    case ListLayout::Compact: return l.capacity ? "compact:" + std::to_string(l.capacity) : "compact";
    case ListLayout::Bitmask: return "bitmask";
    }
    return "?";
}

ListSpec parseListSpec(const std::string& text) {
    const auto parts = splitOn(text, ':');
    ListSpec l;
    std::uint64_t n = 0;
    if (parts[0] == "tile" && parts.size() == 1) {
        l.kind = ListKind::Tile;
    } else if (parts[0] == "halfz" && parts.size() == 1) {
        l.kind = ListKind::HalfZ;
    } else if ((parts[0] == "froxel" || parts[0] == "cells") && (parts.size() == 2 || parts.size() == 3) &&
               parseUint(parts[1], n) && n >= 1 && n <= 32 &&
               (parts.size() == 2 || parts[2] == "log" || parts[2] == "linear")) {
        l.kind = parts[0] == "froxel" ? ListKind::Froxel : ListKind::Cells;
        l.slices = std::uint32_t(n);
        l.slicing = parts.size() == 3 && parts[2] == "linear" ? Slicing::Linear : Slicing::Log;
    } else {
        throw SettingsError("lists", "'" + text + "' is not tile, halfz, froxel:N[:log|linear] or cells:N[:log|linear] (N in 1..32)");
    }
    return l;
}

std::string validationGist(const std::string& message) {
    // "error: VUID-x: Validation Error: [ VUID-x ] Object 0: ...; | MessageID
    // = 0x.. | what is wrong The Vulkan spec states: ..." -> "error: VUID-x:
    // what is wrong".
    static const std::regex layer(R"(^(.*?: )?Validation Error: .*?\| MessageID = 0x[0-9a-fA-F]+ \| (.*?)( The Vulkan spec states:.*)?$)");
    std::smatch m;
    if (!std::regex_match(message, m, layer)) return message;
    return m[1].str() + m[2].str();
}

std::string toString(const ListSpec& l) {
    switch (l.kind) {
    case ListKind::Tile: return "tile";
    case ListKind::HalfZ: return "halfz";
    case ListKind::Froxel: return "froxel:" + std::to_string(l.slices) + ":" + toString(l.slicing);
    case ListKind::Cells: return "cells:" + std::to_string(l.slices) + ":" + toString(l.slicing);
    }
    return "?";
}

std::uint64_t layoutWords(const LayoutSpec& layout, std::uint64_t lists, std::uint64_t lights) {
    switch (layout.kind) {
    case ListLayout::Fixed: return lists * (std::uint64_t(layout.capacity) + 1);
    case ListLayout::Bitmask: return lists * std::max<std::uint64_t>(1, (lights + 31) / 32);
    case ListLayout::Compact: {
        const std::uint64_t entries = layout.capacity ? layout.capacity : 64 * lists;
        return 1 + 2 * lists + entries;
    }
    }
    return 0;
}

namespace {

// Where a line holds the settings tag as a comment ("// lightcull: ...", or
// " * lightcull: ..." inside a block comment): the text after the tag, else
// npos.
// Where a comment line's text starts (past "//", "/*" or a block's "*" and
// the spaces and stars after them); npos for a line that is not a comment.
std::size_t commentTextStart(const std::string& line) {
    std::size_t i = line.find_first_not_of(" \t");
    if (i == std::string::npos) return std::string::npos;
    if (line.compare(i, 2, "//") == 0 || line.compare(i, 2, "/*") == 0) i += 2;
    else if (line[i] == '*') i += 1;
    else return std::string::npos;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '*' || line[i] == '/')) ++i;
    return i;
}

const std::array<std::string, 3> kSettingsFlags = {"--layout", "--lists", "--entry"};

std::size_t settingsTagEnd(const std::string& line) {
    const std::string tag = "lightcull:";
    const std::size_t i = commentTextStart(line);
    return i != std::string::npos && line.compare(i, tag.size(), tag) == 0 ? i + tag.size() : std::string::npos;
}

// A comment that means to be the settings line but is not written as one:
// "LightCull: --layout ...", "lightcull --layout ...", "lightcull : --lists
// ..." (silently skipped, the shader would run with the defaults).
bool looksLikeSettings(const std::string& line) {
    std::size_t i = commentTextStart(line);
    if (i == std::string::npos) return false;
    std::string word = line.substr(i, 9);
    for (char& c : word) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (word != "lightcull") return false;
    i += 9;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == ':')) ++i;
    for (const std::string& flag : kSettingsFlags)
        if (line.compare(i, flag.size(), flag) == 0) return true;
    return false;
}

} // namespace

void applyShaderHeader(const std::string& text, const std::string& path, CustomShaderOptions& o, bool layoutGiven,
                       bool listsGiven, bool entryGiven) {
    // The settings line sits in the file's leading block: comments (a
    // licence header is normal in ported code), blank lines and preprocessor
    // lines (#version, #extension) before the first line of code.
    std::istringstream lines(text);
    std::string line, settings;
    int number = 0, settingsLine = 0, firstCode = 0;
    bool inBlock = false;
    while (std::getline(lines, line)) {
        ++number;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const std::size_t tagEnd = settingsTagEnd(line);
        const std::size_t first = line.find_first_not_of(" \t");
        const bool code = !inBlock && first != std::string::npos && line.compare(first, 2, "//") != 0 &&
                          line.compare(first, 2, "/*") != 0 && line[first] != '#';
        if (tagEnd != std::string::npos) {
            if (firstCode)
                throw InputError(path, "", number,
                                 "lightcull settings: this line must be in the comment block at the top of the file, "
                                 "before the first line of code (line " + std::to_string(firstCode) + ")");
            if (settingsLine)
                throw InputError(path, "", number,
                                 "lightcull settings: a second settings line (the first is line " +
                                     std::to_string(settingsLine) + "): keep one");
            settings = line.substr(tagEnd);
            if (const auto close = settings.find("*/"); close != std::string::npos) settings.resize(close);
            settingsLine = number;
        } else if (!firstCode && looksLikeSettings(line)) {
            throw InputError(path, "", number,
                             "lightcull settings: write this line as '// lightcull: --layout ... --lists ...' "
                             "(lower case, the colon right after lightcull), or it is not read");
        } else if (code && !firstCode) {
            firstCode = number;
        }
        // Block comments: track whether the next line starts inside one.
        for (std::size_t i = 0; i + 1 < line.size(); ++i) {
            if (!inBlock && line.compare(i, 2, "//") == 0) break;
            if (!inBlock && line.compare(i, 2, "/*") == 0) inBlock = true, ++i;
            else if (inBlock && line.compare(i, 2, "*/") == 0) inBlock = false, ++i;
        }
    }
    if (!settingsLine) return;
    std::istringstream words(settings);
    std::string flag, value;
    std::set<std::string> seen;
    while (words >> flag) {
        const std::size_t eq = flag.find('=');
        const bool joined = flag.rfind("--", 0) == 0 && eq != std::string::npos; // --layout=fixed:64, as the CLI takes
        if (joined) value = flag.substr(eq + 1), flag.resize(eq);
        if (std::find(kSettingsFlags.begin(), kSettingsFlags.end(), flag) == kSettingsFlags.end())
            throw InputError(path, "", settingsLine,
                             "lightcull settings: unknown flag '" + flag + "' (--layout, --lists, --entry)");
        if (!joined && !(words >> value))
            throw InputError(path, "", settingsLine, "lightcull settings: " + flag + " needs a value");
        if (!seen.insert(flag).second)
            throw InputError(path, "", settingsLine, "lightcull settings: " + flag + " given twice: keep one");
        try {
            if (flag == "--layout") {
                const LayoutSpec layout = parseLayout(value);
                o.headerLayout = toString(layout);
                if (!layoutGiven) o.layout = layout;
            } else if (flag == "--lists") {
                if (!listsGiven) o.lists = parseListSpec(value);
            } else { // --entry
                if (!entryGiven) o.entry = value;
            }
        } catch (const SettingsError& e) {
            throw InputError(path, "", settingsLine, std::string("lightcull settings: ") + e.what());
        }
    }
}

CustomShaderOptions shaderOptionsFromFile(const std::string& path, const std::string& layout, const std::string& lists,
                                          const std::string& entry) {
    CustomShaderOptions o;
    o.path = path;
    if (!layout.empty()) o.layout = parseLayout(layout);
    if (!lists.empty()) o.lists = parseListSpec(lists);
    if (!entry.empty()) o.entry = entry;
    if (fs::path(path).extension() != ".spv") {
        std::ifstream in(path, std::ios::binary);
        if (!in) throw InputError(path, "", 0, "cannot open shader for reading");
        std::ostringstream text;
        text << in.rdbuf();
        applyShaderHeader(detail::withoutByteOrderMark(text.str()), path, o, !layout.empty(), !lists.empty(),
                          !entry.empty());
    }
    return o;
}

void decodeLists(const std::vector<std::uint32_t>& words, const LayoutSpec& layout, std::uint32_t lightCount,
                 CullResult& result, CustomCullReport& report) {
    const std::size_t lists = result.listOffset.size();
    if (words.size() < layoutWords(layout, lists, lightCount))
        throw Error("the list buffer holds " + std::to_string(words.size()) + " words; layout " + toString(layout) +
                    " with " + std::to_string(lists) + " lists and " + std::to_string(lightCount) + " lights needs " +
                    std::to_string(layoutWords(layout, lists, lightCount)));
    std::vector<std::vector<std::uint32_t>> perList(lists);
    if (layout.kind == ListLayout::Fixed) {
        const std::uint64_t n = layout.capacity;
        for (std::size_t l = 0; l < lists; ++l) {
            const std::uint64_t base = l * (n + 1);
            const std::uint64_t count = words[base];
            if (count > n) {
                ++report.overflowLists;
                report.overflowedListIds.push_back(std::uint32_t(l));
                report.overflowEntries += count - n;
            }
            for (std::uint64_t i = 0; i < std::min(count, n); ++i) perList[l].push_back(words[base + 1 + i]);
        }
    } else if (layout.kind == ListLayout::Bitmask) {
        const std::uint64_t w = std::max<std::uint64_t>(1, (std::uint64_t(lightCount) + 31) / 32);
        for (std::size_t l = 0; l < lists; ++l)
            for (std::uint64_t k = 0; k < w; ++k)
                for (std::uint32_t bits = words[l * w + k]; bits; bits &= bits - 1)
                    perList[l].push_back(std::uint32_t(k * 32 + std::uint32_t(__builtin_ctz(bits))));
    } else {
        const std::uint64_t cap = layout.capacity ? layout.capacity : 64 * std::uint64_t(lists);
        const std::uint64_t start = 1 + 2 * std::uint64_t(lists);
        for (std::size_t l = 0; l < lists; ++l) {
            const std::uint64_t offset = words[1 + 2 * l], count = words[2 + 2 * l];
            const std::uint64_t kept = offset >= cap ? 0 : std::min(count, cap - offset);
            if (kept < count) {
                ++report.overflowLists;
                report.overflowedListIds.push_back(std::uint32_t(l));
                report.overflowEntries += count - kept;
            }
            for (std::uint64_t i = 0; i < kept; ++i) perList[l].push_back(words[start + offset + i]);
        }
    }
    assignLists(perList, lightCount, result, report);
}

const char* toString(MissCause c) {
    switch (c) {
    case MissCause::CullingTest: return "culling test";
    case MissCause::ListFull: return "list full";
    case MissCause::LightLimit: return "light limit";
    case MissCause::InvalidIndex: return "invalid index";
    }
    return "?";
}

const char* jsonName(MissCause c) {
    switch (c) {
    case MissCause::CullingTest: return "culling_test";
    case MissCause::ListFull: return "list_full";
    case MissCause::LightLimit: return "light_limit";
    case MissCause::InvalidIndex: return "invalid_index";
    }
    return "?";
}

std::vector<MissedLight> locateFalseNegatives(const RunOutput& run, const Projection& proj) {
    std::vector<MissedLight> out;
    const ListLimits& limits = run.result.limits;
    auto causeOf = [&](std::uint32_t list, std::uint32_t light) {
        if (limits.isOverLimit(light)) return MissCause::LightLimit;
        if (limits.dropped(list, light)) return MissCause::ListFull;
        if (!run.custom) return MissCause::CullingTest;
        const auto& full = run.custom->overflowedListIds;
        const auto& bad = run.custom->invalidIndexListIds;
        if (std::binary_search(full.begin(), full.end(), list)) return MissCause::ListFull;
        if (std::binary_search(bad.begin(), bad.end(), list)) return MissCause::InvalidIndex;
        return MissCause::CullingTest;
    };
    const CullResult& r = run.result;
    if (!run.truthComputed || run.truth.metrics.falseNegatives == 0) return out;
    const std::uint32_t per = r.algorithm == Algorithm::All ? 0 : std::max(r.listsPerTile, 1u);
    // Tile by tile, on every core (a run missing thousands of lights has
    // misses in most tiles); concatenated in tile order.
    const std::uint32_t tileCount = r.grid.tileCount();
    std::vector<std::vector<MissedLight>> perTile(tileCount);
    std::atomic<std::uint32_t> nextTile{0};
    auto work = [&] {
        for (std::uint32_t t; (t = nextTile++) < tileCount;) {
            bool any = false;
            if (per == 0) any = true;
            for (std::uint32_t k = 0; per && k < per && !any; ++k)
                any = run.truth.listFalseNegatives[t * per + k] > 0;
            if (!any) continue;
            // (list, light) -> pixels
            std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> missed;
            const TileGrid::Rect rect = r.grid.tileRect(t % r.grid.tilesX, t / r.grid.tilesX);
            // The tile's points and their box: only a light whose sphere reaches
            // the box can be needed here (the point of the box nearest its centre
            // is no farther than any point in it, in floating point too).
            std::vector<std::pair<glm::dvec3, std::uint32_t>> points; // (point, its list)
            const double inf = std::numeric_limits<double>::infinity();
            glm::dvec3 lo(inf), hi(-inf);
            for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
                for (std::uint32_t x = rect.x0; x < rect.x1; ++x) {
                    if (!run.depth.hasGeometry(x, y)) continue;
                    const glm::dvec3 p = proj.viewPositionFromDepth(x, y, run.depth.at(x, y));
                    points.emplace_back(p, r.listOfPixel(x, y, -p.z));
                    lo = glm::min(lo, p), hi = glm::max(hi, p);
                }
            std::vector<std::uint32_t> candidates;
            for (std::uint32_t i = 0; i < run.lights.size() && !points.empty(); ++i)
                if (detail::lightContains(run.lights.centers[i], run.lights.radii[i],
                                          glm::clamp(run.lights.centers[i], lo, hi)))
                    candidates.push_back(i);
            // Per list of the tile, the candidates it lacks: only those are
            // tested at its points (a list holds most of what its pixels need).
            std::map<std::uint32_t, std::vector<std::uint32_t>> lacks; // list -> candidates not in it
            for (const auto& [p, list] : points) {
                auto [at, fresh] = lacks.try_emplace(list);
                if (fresh) {
                    const auto first = r.lightIndices.begin() + r.listOffset[list];
                    std::set_difference(candidates.begin(), candidates.end(), first,
                                        first + r.listCount[list], std::back_inserter(at->second));
                }
                for (const std::uint32_t i : at->second)
                    if (detail::lightNeeds(run.lights, i, p)) ++missed[{list, i}];
            }
            for (const auto& [key, pixels] : missed)
                perTile[t].push_back({t, key.first, key.second, pixels, causeOf(key.first, key.second)});
        }
    };
    std::vector<std::thread> helpers(std::min(std::max(std::thread::hardware_concurrency(), 1u), 8u) - 1);
    for (std::thread& h : helpers)
        h = std::thread(work);
    work();
    for (std::thread& h : helpers)
        h.join();
    for (const auto& v : perTile)
        out.insert(out.end(), v.begin(), v.end());
    std::stable_sort(out.begin(), out.end(), [](const MissedLight& a, const MissedLight& b) {
        return a.cause != b.cause ? a.cause < b.cause : a.pixels > b.pixels;
    });
    return out;
}

CullResult ShaderLists::makeLists(const Scene&, const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                                  const ViewLights& lights) {
    return runCustomShader(options_, depth, proj, grid, lights, report_);
}

std::shared_ptr<const CustomCullReport> ShaderLists::report() const {
    return std::make_shared<CustomCullReport>(report_);
}

CullResult DumpLists::makeLists(const Scene&, const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                                const ViewLights& lights) {
    const CullResult skeleton = ruleSkeleton(depth, proj, grid, lights, lists_);
    CullResult r = skeleton;
    report_.source = path_;
    report_.layout = toString(layout_);
    report_.lists = toString(lists_);
    const auto lightCount = std::uint32_t(lights.size());
    const std::string ext = inMemory_ ? std::string() : fs::path(path_).extension().string();
    const std::string bytes = inMemory_ ? std::string() : detail::readWholeFile(path_);
    if (inMemory_) {
        const std::uint64_t need = layoutWords(layout_, r.listOffset.size(), lightCount);
        if (words_.size() < need)
            throw InputError(path_, "", 0, std::to_string(words_.size()) + " words, but " + toString(layout_) +
                                                " with " + std::to_string(r.listOffset.size()) + " lists (" +
                                                toString(lists_) + ") and " + std::to_string(lightCount) +
                                                " lights needs " + std::to_string(need));
        decodeLists(words_, layout_, lightCount, r, report_);
    } else if (ext == ".csv") {
        // One line per list: "list,light,light,...". Lists not named are empty.
        std::vector<std::vector<std::uint32_t>> perList(r.listOffset.size());
        std::istringstream in(bytes);
        std::string line;
        int lineNo = 0;
        if (bytes.find_first_not_of(" \t\r\n") == std::string::npos)
            throw InputError(path_, "", 0, "empty: not a list dump (a CSV holds a line per list: list,light,light,...)");
        while (std::getline(in, line)) {
            ++lineNo;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            // A header: a first line with a letter in it ("list,lights").
            const bool header = lineNo == 1 && std::any_of(line.begin(), line.end(), [](unsigned char c) {
                                    return std::isalpha(c) != 0;
                                });
            if (line.empty() || header) continue;
            const auto fields = splitOn(line, ',');
            std::uint64_t list = 0;
            if (!parseUint(fields[0], list))
                throw InputError(path_, "", lineNo, "'" + fields[0] + "' is not a list index");
            if (list >= perList.size())
                throw InputError(path_, "", lineNo, "list " + std::to_string(list) + " is outside 0.." +
                                                            std::to_string(perList.size() - 1) + " (" + toString(lists_) + ")");
            for (std::size_t k = 1; k < fields.size(); ++k) {
                std::uint64_t v = 0;
                if (fields[k].empty()) continue;
                if (!parseUint(fields[k], v) || v > 0xFFFFFFFFull)
                    throw InputError(path_, "", lineNo, "'" + fields[k] + "' is not a light index");
                perList[list].push_back(std::uint32_t(v));
            }
        }
        assignLists(perList, lightCount, r, report_);
    } else {
        if (bytes.size() % 4 != 0)
            throw InputError(path_, "", 0, std::to_string(bytes.size()) + " bytes is not a whole number of 32-bit words");
        const std::uint64_t need = layoutWords(layout_, r.listOffset.size(), lightCount);
        if (bytes.size() / 4 < need)
            throw InputError(path_, "", 0, std::to_string(bytes.size() / 4) + " words, but " + toString(layout_) +
                                                   " with " + std::to_string(r.listOffset.size()) + " lists (" + toString(lists_) +
                                                   ") and " + std::to_string(lightCount) + " lights needs " + std::to_string(need));
        if (bytes.size() / 4 > need)
            report_.warnings.push_back(
                fs::path(path_).filename().string() + ": " + std::to_string(bytes.size() / 4) + " words, of which " +
                toString(layout_) + " with " + std::to_string(r.listOffset.size()) + " lists (" + toString(lists_) +
                ") reads the first " + std::to_string(need) +
                ": a padded buffer is fine, but check the layout, --tile and the resolution");
        std::vector<std::uint32_t> words(bytes.size() / 4);
        for (std::size_t i = 0; i < words.size(); ++i) {
            const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + 4 * i);
            words[i] = std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
        }
        decodeLists(words, layout_, lightCount, r, report_);
    }
    r.backend = inMemory_ ? "capture" : "dump";
    r.device = "engine lists from " + (inMemory_ ? path_ : fs::path(path_).filename().string());
    r.timingMethod = inMemory_ ? "not timed (lists read from a capture)" : "not timed (lists read from a file)";
    r.timings.cullMs = -1;
    r.volumeTests = 0;
    compareWithBuiltin(r, skeleton, report_);
    return r;
}

std::shared_ptr<const CustomCullReport> DumpLists::report() const {
    return std::make_shared<CustomCullReport>(report_);
}

RunOutput runCustomPipeline(const Scene& scene, const CustomShaderOptions& options, CullBackend& depthBackend,
                            const RunOptions& runOptions, CustomCullReport& report, const DepthImage* depthOverride) {
    ShaderLists lists(options, report);
    RunOptions o = runOptions;
    if (depthOverride) o.reuseDepth = depthOverride;
    return runPipeline(scene, lists, &depthBackend, o);
}

RunOutput checkListDump(const Scene& scene, const std::string& listsPath, const LayoutSpec& layout,
                        const ListSpec& lists, const DepthImage& depth, const RunOptions& runOptions,
                        CustomCullReport& report) {
    DumpLists dump(listsPath, layout, lists, report);
    RunOptions o = runOptions;
    o.reuseDepth = &depth;
    return runPipeline(scene, dump, nullptr, o);
}

DepthImage loadDepthFile(const std::string& path, const Projection& proj) {
    DepthImage d;
    d.width = proj.width();
    d.height = proj.height();
    d.clearDepth = float(proj.clearDepth());
    const std::size_t n = std::size_t(d.width) * d.height;
    const std::string ext = fs::path(path).extension().string();
    if (ext == ".png") {
        png_image img;
        std::memset(&img, 0, sizeof img);
        img.version = PNG_IMAGE_VERSION;
        if (!png_image_begin_read_from_file(&img, path.c_str()))
            throw InputError(path, "", 0, std::string("not a readable PNG: ") + img.message);
        if (img.width != d.width || img.height != d.height) {
            png_image_free(&img);
            throw InputError(path, "", 0, std::to_string(img.width) + "x" + std::to_string(img.height) +
                                              " pixels, but the camera is " + std::to_string(d.width) + "x" +
                                              std::to_string(d.height));
        }
        // Depth is 16-bit grey: an 8-bit file holds 1/256 of the precision
        // and libpng would gamma-decode it, a colour one is no depth at all.
        if (!(img.format & PNG_FORMAT_FLAG_LINEAR) || (img.format & PNG_FORMAT_FLAG_COLOR)) {
            const bool colour = img.format & PNG_FORMAT_FLAG_COLOR;
            png_image_free(&img);
            throw InputError(path, "", 0,
                             std::string(colour ? "a colour" : "an 8-bit") +
                                 " PNG; depth is read from 16-bit greyscale PNGs (0..65535 is window depth 0..1) "
                                 "or raw float32");
        }
        img.format = PNG_FORMAT_LINEAR_Y; // 16-bit grey, no gamma applied
        std::vector<std::uint16_t> px(n);
        if (!png_image_finish_read(&img, nullptr, px.data(), 0, nullptr))
            throw InputError(path, "", 0, std::string("cannot decode: ") + img.message);
        d.depth.resize(n);
        for (std::size_t i = 0; i < n; ++i) d.depth[i] = float(px[i]) / 65535.0f;
    } else {
        std::error_code ec;
        const auto size = fs::file_size(path, ec);
        if (ec) throw InputError(path, "", 0, "cannot read: " + ec.message());
        if (size != n * 4)
            throw InputError(path, "", 0, std::to_string(size) + " bytes, but raw float32 depth of a " +
                                              std::to_string(d.width) + "x" + std::to_string(d.height) + " camera is " +
                                              std::to_string(n * 4));
        std::ifstream in(path, std::ios::binary);
        d.depth.resize(n);
        in.read(reinterpret_cast<char*>(d.depth.data()), std::streamsize(n * 4));
        if (!in) throw InputError(path, "", 0, "read error");
    }
    for (std::size_t i = 0; i < n; ++i)
        if (!(d.depth[i] >= 0.0f && d.depth[i] <= 1.0f))
            throw InputError(path, "", 0, "pixel " + std::to_string(i % d.width) + "," + std::to_string(i / d.width) +
                                              " has window depth " + std::to_string(d.depth[i]) + ", outside [0, 1]");
    return d;
}

} // namespace lc
