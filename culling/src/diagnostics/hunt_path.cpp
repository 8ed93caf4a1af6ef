// The hunt along a camera path (culling/diagnostics/hunt.hpp, `lightcull
// hunt --path`): every frame judged, the worst one shrunk, a CSV and an SVG
// plot of the false negatives per frame.
#include "culling/diagnostics/hunt.hpp"

#include "culling/core/file_io.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;

namespace lc {

HuntPathResult huntPath(const HuntOptions& options, const Scene& scene, const CameraPath& path, CullBackend& backend) {
    HuntPathResult r;
    r.description = path.description;
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    double lastReport = 0;
    HuntCoverage cov;
    Scene frame = scene;
    for (std::size_t i = 0; i < path.frames.size(); ++i) {
        if (options.cancel && options.cancel->cancelled) {
            r.cancelled = true;
            break;
        }
        frame.camera = path.frames[i].camera;
        HuntPathFrameResult fr;
        fr.time = path.frames[i].time;
        fr.verdict = judgeHuntTrial(frame, options, backend);
        ++cov.trials;
        cov.emptyViews += fr.verdict.geometryPixels == 0 && !fr.verdict.fails;
        cov.overCapacity += fr.verdict.overCapacity && !fr.verdict.fails;
        if (fr.verdict.fails) {
            ++r.failingFrames;
            if (!r.worst || fr.verdict.falseNegatives > r.frames[*r.worst].verdict.falseNegatives) r.worst = i;
        }
        r.frames.push_back(std::move(fr));
        if (options.progress && elapsed() - lastReport >= 1.0) {
            lastReport = elapsed();
            options.progress(cov, lastReport);
        }
    }
    if (r.worst) {
        const std::size_t w = *r.worst;
        HuntFailure f;
        f.trial = w;
        f.original = scene;
        f.original.camera = path.frames[w].camera;
        char where[96];
        std::snprintf(where, sizeof where, "frame %zu (t = %g s) of %zu", w, path.frames[w].time, path.frames.size());
        f.pathFrame = std::string(where) + " (" + path.description + "); " + std::to_string(r.failingFrames) +
                      " frame" + (r.failingFrames == 1 ? "" : "s") + " fail";
        f.varied = "the camera along the path";
        f.shrunk = shrinkHuntFailure(f.original, options, backend, &f.shrinkRuns);
        f.verdict = judgeHuntTrial(f.shrunk, options, backend);
        if (!f.verdict.fails) {
            f.shrunk = f.original;
            f.verdict = r.frames[w].verdict;
        }
        r.failure = std::move(f);
    }
    r.seconds = elapsed();
    if (options.progress) options.progress(cov, r.seconds);
    return r;
}

HuntResult huntResultOf(const HuntPathResult& r) {
    HuntResult h;
    h.coverage.trials = r.frames.size();
    for (const HuntPathFrameResult& f : r.frames) {
        h.coverage.emptyViews += f.verdict.geometryPixels == 0 && !f.verdict.fails;
        h.coverage.overCapacity += f.verdict.overCapacity && !f.verdict.fails;
    }
    h.seconds = r.seconds;
    h.failure = r.failure;
    h.cancelled = r.cancelled;
    h.path = r.description;
    return h;
}

namespace {

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
    return q + "\"";
}

std::string xmlEscaped(const std::string& s) {
    std::string o;
    for (char c : s) {
        if (c == '<') o += "&lt;";
        else if (c == '>') o += "&gt;";
        else if (c == '&') o += "&amp;";
        else if (c == '"') o += "&quot;";
        else o += c;
    }
    return o;
}

} // namespace

void writeHuntPathReport(const HuntPathResult& r, const CameraPath& path, const std::string& dir) {
    const fs::path out(dir);
    std::ostringstream csv;
    csv << "frame,time,false_negatives,geometry_pixels,invalid_indices,duplicate_indices,overflow_lists,"
           "missed_light,missed_tile,fails,property\n";
    for (std::size_t i = 0; i < r.frames.size(); ++i) {
        const HuntVerdict& v = r.frames[i].verdict;
        char t[32];
        std::snprintf(t, sizeof t, "%.9g", r.frames[i].time);
        csv << i << ',' << t << ',' << v.falseNegatives << ',' << v.geometryPixels << ',' << v.invalidIndices << ','
            << v.duplicateIndices << ',' << v.overflowLists << ',' << (v.miss ? std::to_string(v.miss->light) : "")
            << ',' << (v.miss ? std::to_string(v.miss->tile) : "") << ',' << (v.fails ? 1 : 0) << ','
            << csvField(v.property) << '\n';
    }
    writeFileSynced((out / "path.csv").string(), csv.str());

    // The plot: false negatives per frame, failing frames in red.
    const double W = 900, H = 320, L = 70, R = 20, T = 40, B = 50;
    std::uint64_t maxFn = 1;
    for (const auto& f : r.frames) maxFn = std::max(maxFn, f.verdict.falseNegatives);
    const std::size_t n = std::max<std::size_t>(r.frames.size(), 1);
    auto x = [&](std::size_t i) { return L + (W - L - R) * (n == 1 ? 0.5 : double(i) / double(n - 1)); };
    auto y = [&](std::uint64_t fn) { return H - B - (H - T - B) * double(fn) / double(maxFn); };
    std::ostringstream svg;
    char buf[1024];
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W
        << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    std::string title = "False negatives per frame: " + path.description;
    if (r.worst)
        title += "; worst frame " + std::to_string(*r.worst) + " (" +
                 std::to_string(r.frames[*r.worst].verdict.falseNegatives) + ")";
    else
        title += "; no frame misses a light";
    svg << "<text x=\"" << L << "\" y=\"22\" font-size=\"14\">" << xmlEscaped(title) << "</text>\n";
    std::snprintf(buf, sizeof buf,
                  "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"black\"/>\n"
                  "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"black\"/>\n",
                  L, H - B, W - R, H - B, L, T, L, H - B);
    svg << buf;
    std::snprintf(buf, sizeof buf,
                  "<text x=\"%g\" y=\"%g\" text-anchor=\"end\">%llu</text>\n<text x=\"%g\" y=\"%g\" "
                  "text-anchor=\"end\">0</text>\n",
                  L - 6, T + 4, static_cast<unsigned long long>(maxFn), L - 6, H - B + 4);
    svg << buf;
    std::snprintf(buf, sizeof buf,
                  "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">0</text>\n<text x=\"%g\" y=\"%g\" "
                  "text-anchor=\"middle\">%zu</text>\n<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">frame</text>\n"
                  "<text x=\"16\" y=\"%g\" transform=\"rotate(-90 16 %g)\" text-anchor=\"middle\">false "
                  "negatives</text>\n",
                  x(0), H - B + 18, x(n - 1), H - B + 18, n - 1, (L + W - R) / 2, H - B + 36, (T + H - B) / 2,
                  (T + H - B) / 2);
    svg << buf;
    if (!r.frames.empty()) {
        svg << "<polyline fill=\"none\" stroke=\"#1f5fa8\" stroke-width=\"1.5\" points=\"";
        for (std::size_t i = 0; i < r.frames.size(); ++i) {
            std::snprintf(buf, sizeof buf, "%.2f,%.2f ", x(i), y(r.frames[i].verdict.falseNegatives));
            svg << buf;
        }
        svg << "\"/>\n";
    }
    for (std::size_t i = 0; i < r.frames.size(); ++i) {
        if (!r.frames[i].verdict.fails) continue;
        std::snprintf(buf, sizeof buf, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%g\" fill=\"#c0392b\"/>\n", x(i),
                      y(r.frames[i].verdict.falseNegatives), r.worst && *r.worst == i ? 5.0 : 2.5);
        svg << buf;
    }
    svg << "</svg>\n";
    writeFileSynced((out / "path.svg").string(), svg.str());
}

} // namespace lc
