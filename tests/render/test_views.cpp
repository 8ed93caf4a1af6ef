// Render tests: screenshots of the camera view (shaded scene, tile grid, heat
// map, legend, selected tile) and the inspector view (meshes, translucent light
// spheres, selected light, culling frustum, drag handle) of a fixed scene built
// here (independent of the built-in scenes), compared with PNG baselines.
//
// Tolerance: a pixel differs when any channel differs by more than 40 (of
// 255); a view fails when more than 0.5% of its pixels differ. Why: Mesa's
// llvmpipe is deterministic for one build, but another Mesa/VTK/FreeType
// version moves anti-aliased edges and glyph outlines by a pixel and shifts
// blended colours by a few levels; a real regression (camera framing, colour
// map, a missing or misplaced actor, a wrong tile) changes far more than 0.5%.
//
// The whole-image limit alone lets a small wrong region through: one tile of
// a 320x180 image at 16 px covers 0.4% of a 720x360 view, so a tile in the
// wrong colour, or the selected outline on the wrong tile, passed. Camera
// views are therefore also compared tile by tile: no tile may have more than
// 10% of its pixels differ (a mesh edge moved by a pixel across a tile
// changes about 3%; a tile recoloured by one heat step, or losing or gaining
// the selection outline, changes 20% or more).
//
// A missing baseline FAILS and writes the candidate (and, on a mismatch, a
// diff image) to LC_RENDER_OUT_DIR in the build tree; look at it, then copy it
// to tests/render/baselines/.

#include "../ui/studio_test_support.hpp"
#include "../support/box_mesh.hpp"

#include "views/camera_view.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "views/overlay_actors.hpp"

#include "culling/core/backend.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "culling/core/pipeline.hpp"

#include <QDir>
#include <QImage>

#include <vtkCamera.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include <cmath>
#include <memory>

using namespace lcui;

namespace {

constexpr int kChannelTolerance = 40;
constexpr double kMaxDifferingFraction = 0.005;
constexpr double kMaxDifferingFractionPerTile = 0.10;

// The rectangles of the culling image's tiles in a camera view's framebuffer
// (device pixels, Qt rows going down), as the view draws them.
std::vector<std::pair<QString, QRect>> tileRegions(const CameraView& view, const lc::TileGrid& g) {
    std::vector<std::pair<QString, QRect>> out;
    const QRect img = view.imageRect();
    const double dpr = view.devicePixelRatioF();
    const double sx = img.width() * dpr / g.width, sy = img.height() * dpr / g.height;
    for (std::uint32_t ty = 0; ty < g.tilesY; ++ty)
        for (std::uint32_t tx = 0; tx < g.tilesX; ++tx) {
            const auto r = g.tileRect(tx, ty);
            const QRect px(QPoint(int(img.left() * dpr + r.x0 * sx), int(img.top() * dpr + r.y0 * sy)),
                           QPoint(int(img.left() * dpr + r.x1 * sx) - 1, int(img.top() * dpr + r.y1 * sy) - 1));
            out.emplace_back(QString("tile %1,%2").arg(tx).arg(ty), px);
        }
    return out;
}

using lctest::addBox;

// A ground slab, three blocks and a tall column; six coloured lights; a
// camera looking down at it. Asymmetric on purpose (a flipped image shows).
lc::Scene fixedScene() {
    lc::Scene s;
    s.name = "render-test";
    lc::Mesh m;
    m.name = "blocks";
    addBox(m, {-8, -0.2f, -8}, {8, 0, 8});
    addBox(m, {-5, 0, -4}, {-3, 2, -2});
    addBox(m, {1, 0, -6}, {4, 1, -3});
    addBox(m, {2, 0, 1}, {3, 1.5f, 2});
    addBox(m, {-1.5f, 0, -1.5f}, {-0.5f, 5, -0.5f});
    s.meshes.push_back(m);
    const glm::dvec3 pos[6] = {{-4, 2.5, -3}, {2.5, 1.5, -4.5}, {2.5, 2, 1.5}, {-1, 5.5, -1}, {5, 0.5, 5}, {-6, 1, 4}};
    const glm::dvec3 col[6] = {{1, 0.2, 0.2}, {0.2, 1, 0.3}, {0.3, 0.4, 1}, {1, 1, 0.3}, {1, 0.5, 0.1}, {0.7, 0.3, 1}};
    for (int i = 0; i < 6; ++i) {
        lc::PointLight l;
        l.name = "light " + std::to_string(i);
        l.position = pos[i];
        l.color = col[i];
        l.intensity = 1.0 + i;
        l.minIntensity = 0.25; // radii sqrt(I/0.25): 2 .. 4.9
        s.lights.push_back(l);
    }
    s.camera.position = {3, 7, 13};
    s.camera.target = {0, 1, -1};
    s.camera.up = {0, 1, 0};
    s.camera.fovYDeg = 50;
    s.camera.nearPlane = 0.5;
    s.camera.farPlane = 100;
    s.camera.width = 320;
    s.camera.height = 180;
    s.camera.tileSize = 16;
    return s;
}

// The render tier's fixture: `doc` holds the fixed scene culled on the CPU
// reference with `algorithm` (and `cells`), the run set as its output.
std::shared_ptr<const lc::RunOutput> cullFixedScene(Document& doc, lc::Algorithm algorithm, std::uint32_t cells = 32,
                                                    bool shadedImages = false) {
    doc.resetScene(fixedScene(), {});
    lc::CullSettings s = doc.runs().settings();
    s.algorithm = algorithm;
    s.cells = cells;
    doc.runs().setSettings(s);
    auto backend = lc::makeBackend("cpu");
    lc::RunOptions opt;
    opt.truthOptions.imageError = shadedImages;
    opt.keepShadedImages = shadedImages;
    auto run = std::make_shared<lc::RunOutput>(lc::runPipeline(doc.scene(), doc.runs().settings(), *backend, opt));
    if (run->truth.metrics.falseNegatives != 0 || !doc.runs().setRunOutput(run, 1)) return nullptr;
    return run;
}

struct Comparison {
    bool ok = false;
    QString message;
};

Comparison compareWithBaseline(const QImage& shot, const QString& name,
                               const std::vector<std::pair<QString, QRect>>& regions = {},
                               const QString& candidateName = {}) {
    const QString baselinePath = QString(LC_RENDER_BASELINES) + "/" + name + ".png";
    QDir().mkpath(LC_RENDER_OUT_DIR);
    const QString candidatePath =
        QString(LC_RENDER_OUT_DIR) + "/" + (candidateName.isEmpty() ? name : candidateName) + ".png";
    const QImage img = shot.convertToFormat(QImage::Format_RGB32);
    img.save(candidatePath);
    QImage base;
    if (!base.load(baselinePath))
        return {false, "missing baseline " + baselinePath + "; candidate written to " + candidatePath};
    base = base.convertToFormat(QImage::Format_RGB32);
    if (base.size() != img.size())
        return {false, QString("size %1x%2, baseline %3x%4; candidate %5")
                           .arg(img.width()).arg(img.height()).arg(base.width()).arg(base.height()).arg(candidatePath)};
    QImage diff(img.size(), QImage::Format_RGB32);
    diff.fill(Qt::black);
    qint64 differing = 0;
    for (int y = 0; y < img.height(); ++y) {
        const QRgb* a = reinterpret_cast<const QRgb*>(img.constScanLine(y));
        const QRgb* b = reinterpret_cast<const QRgb*>(base.constScanLine(y));
        for (int x = 0; x < img.width(); ++x) {
            const int d = std::max({std::abs(qRed(a[x]) - qRed(b[x])), std::abs(qGreen(a[x]) - qGreen(b[x])),
                                    std::abs(qBlue(a[x]) - qBlue(b[x]))});
            if (d > kChannelTolerance) {
                ++differing;
                diff.setPixel(x, y, qRgb(255, 0, 0));
            }
        }
    }
    const double fraction = double(differing) / (double(img.width()) * img.height());
    for (const auto& [what, rect] : regions) {
        const QRect r = rect.intersected(img.rect());
        qint64 n = 0;
        for (int y = r.top(); y <= r.bottom(); ++y)
            for (int x = r.left(); x <= r.right(); ++x) n += diff.pixel(x, y) != qRgb(0, 0, 0);
        const double f = r.isEmpty() ? 0.0 : double(n) / (double(r.width()) * r.height());
        if (f > kMaxDifferingFractionPerTile) {
            const QString diffPath = QString(LC_RENDER_OUT_DIR) + "/" + name + "_diff.png";
            diff.save(diffPath);
            return {false, QString("%1: %2 differs in %3% of its pixels (limit %4%); candidate %5, diff %6")
                               .arg(name, what).arg(f * 100, 0, 'f', 1).arg(kMaxDifferingFractionPerTile * 100)
                               .arg(candidatePath, diffPath)};
        }
    }
    if (fraction > kMaxDifferingFraction) {
        const QString diffPath = QString(LC_RENDER_OUT_DIR) + "/" + name + "_diff.png";
        diff.save(diffPath);
        return {false, QString("%1: %2% of pixels differ (limit %3%); candidate %4, diff %5")
                           .arg(name).arg(fraction * 100, 0, 'f', 3).arg(kMaxDifferingFraction * 100)
                           .arg(candidatePath, diffPath)};
    }
    return {true, QString("%1: %2% of pixels differ").arg(name).arg(fraction * 100, 0, 'f', 3)};
}

} // namespace

class RenderTest : public QObject {
    Q_OBJECT

    std::unique_ptr<Document> doc_;

private slots:
    void initTestCase() {
        doc_ = std::make_unique<Document>();
        const auto run = cullFixedScene(*doc_, doc_->runs().settings().algorithm);
        QVERIFY(run);
        doc_->selection().setSelectedLights({1});
        doc_->selection().setSelectedTile(int(run->result.grid.tileIndex(9, 6)));
    }

    void cameraView() {
        CameraView view(doc_.get());
        view.resize(720, 360);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view));
        view.renderNow();
        QTest::qWait(50);
        view.renderNow();
        const QImage shot = view.grabFramebuffer();
        QVERIFY(!shot.isNull());
        QCOMPARE(shot.size(), QSize(720, 360) * view.devicePixelRatio());
        const Comparison c =
            compareWithBaseline(shot, "camera_view", tileRegions(view, doc_->runs().runOutput()->result.grid));
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));
    }

    // The tile-by-tile comparison is what catches a small wrong region: the
    // selection outline on the neighbouring tile changes too few pixels of
    // the whole view for the whole-image limit, and fails the tile check.
    void selectionOnTheWrongTileFailsTheComparison() {
        Document doc;
        const auto run = cullFixedScene(doc, doc.runs().settings().algorithm);
        QVERIFY(run);
        doc.selection().setSelectedLights({1});
        doc.selection().setSelectedTile(int(run->result.grid.tileIndex(10, 6))); // the baseline has 9,6
        CameraView view(&doc);
        view.resize(720, 360);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view));
        view.renderNow();
        QTest::qWait(50);
        view.renderNow();
        const QImage shot = view.grabFramebuffer();
        const Comparison whole = compareWithBaseline(shot, "camera_view", {}, "camera_view_wrong_tile");
        QVERIFY2(whole.ok, qPrintable("the whole-image limit alone: " + whole.message));
        const Comparison tiles =
            compareWithBaseline(shot, "camera_view", tileRegions(view, run->result.grid), "camera_view_wrong_tile");
        QVERIFY2(!tiles.ok, qPrintable(tiles.message));
        QVERIFY2(tiles.message.contains("tile 9,6") || tiles.message.contains("tile 10,6"), qPrintable(tiles.message));
        qInfo("%s", qPrintable(tiles.message));
    }

    void inspectorView() {
        InspectorView view(doc_.get());
        view.resize(640, 480);
        view.show();
        QVERIFY(QTest::qWaitForWindowExposed(&view));
        view.resetCamera();
        view.renderNow();
        QTest::qWait(50);
        view.renderNow();
        const QImage shot = view.grabFramebuffer();
        QVERIFY(!shot.isNull());
        const Comparison c = compareWithBaseline(shot, "inspector_view");
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));
    }

    // Overlays of a selected tile: its frustum, its 2.5d cells (occupied
    // filled, empty outlined), the current light's cell range, the tile's
    // listed lights highlighted and the rest dimmed, and the tiles holding
    // the current light outlined in the camera view (efficiency heat map).
    void tileOverlays() {
        Document doc;
        const auto run = cullFixedScene(doc, lc::Algorithm::TwoPointFiveD, 8);
        QVERIFY(run);
        // The tile with the longest list (a fixed choice: the scene is fixed).
        std::uint32_t tile = 0;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount(); ++t)
            if (run->result.listCount[t] > run->result.listCount[tile]) tile = t;
        const std::uint32_t first = run->result.tileLists(tile).first;
        QVERIFY(run->result.listCount[first] >= 2); // the picture shows listed lights and dimmed others
        doc.selection().setSelectedTile(int(tile));
        doc.selection().setSelectedLights({int(run->result.lightIndices[run->result.listOffset[first]])});
        auto o = doc.viewOptions().overlays();
        o.heat = lc::HeatMode::Efficiency;
        doc.viewOptions().setOverlays(o);

        InspectorView iv(&doc);
        iv.resize(640, 480);
        iv.show();
        QVERIFY(QTest::qWaitForWindowExposed(&iv));
        iv.resetCamera();
        // Close up on the tile's frustum, from the inspector's default direction.
        double b[6];
        iv.overlays()->tileSolid()->GetBounds(b);
        QVERIFY(b[1] > b[0]);
        iv.renderer()->ResetCamera(b);
        iv.renderer()->GetActiveCamera()->Zoom(1.3);
        iv.renderer()->ResetCameraClippingRange();
        iv.renderNow();
        QTest::qWait(50);
        iv.renderNow();
        Comparison c = compareWithBaseline(iv.grabFramebuffer(), "inspector_tile_overlays");
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));

        CameraView cv(&doc);
        cv.resize(720, 360);
        cv.show();
        QVERIFY(QTest::qWaitForWindowExposed(&cv));
        cv.renderNow();
        QTest::qWait(50);
        cv.renderNow();
        c = compareWithBaseline(cv.grabFramebuffer(), "camera_efficiency_reverse", tileRegions(cv, run->result.grid));
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));
    }

    // Frame selected (F) on a tile with its 8 depth cells, and Explain in 3D
    // for a light listed there that no pixel of the tile needs: the plane
    // closest to rejecting it (violet quad) and the tile's pixel nearest the
    // light's sphere joined to it (white); F brings both into view. The inspector's camera is the
    // one frameSelected flies to (no animation) orbited by a fixed angle, so a
    // change in the framing shows here too.
    void framedTileWithExplain() {
        Document doc;
        const auto run = cullFixedScene(doc, lc::Algorithm::TwoPointFiveD, 8);
        QVERIFY(run);
        // The first tile (in tile order: a fixed choice, the scene is fixed)
        // with a false positive.
        const lc::Projection proj(doc.scene().camera);
        int tile = -1, light = -1;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount() && tile < 0; ++t)
            for (const auto& row : lc::tileLightRows(*run, proj, t, -1))
                if (row.verdict == lc::Verdict::FalsePositive) {
                    tile = int(t), light = int(row.light);
                    break;
                }
        QVERIFY(tile >= 0);
        doc.selection().setSelectedTile(tile);
        doc.selection().setSelectedLights({light});

        InspectorView iv(&doc);
        iv.resize(640, 480);
        iv.show();
        QVERIFY(QTest::qWaitForWindowExposed(&iv));
        QVERIFY(iv.frameSelected(0));
        QVERIFY(iv.overlays()->explainPlane()->GetNumberOfCells() > 0);
        QCOMPARE(iv.overlays()->explainPixel()->GetNumberOfPoints(), vtkIdType(2));
        // The deciding plane here is the frustum's right side, seen edge-on
        // from where F looks: orbit a little to see it face-on, as a user would.
        QCOMPARE(iv.overlays()->explanation()->decisivePlane, 1);
        iv.renderer()->GetActiveCamera()->Azimuth(50);
        iv.renderer()->ResetCameraClippingRange();
        iv.renderNow();
        QTest::qWait(50);
        iv.renderNow();
        const Comparison c = compareWithBaseline(iv.grabFramebuffer(), "inspector_framed_tile_explain");
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));
    }

    // The spot handles of the current light (a spot behind the tall column,
    // seen from where the column hides its apex): the direction and angle
    // handles in their layer above the scene, over the column; the cone
    // and the selected light's wireframe. A baseline, not only a picture to
    // look at: handles hidden by geometry, in the wrong place or colour,
    // or a missing cone change far more than the tolerance.
    void spotHandlesOverGeometry() {
        Document doc;
        lc::Scene s = fixedScene();
        lc::PointLight& spot = s.lights[3]; // above the column's top
        spot.kind = lc::LightKind::Spot;
        spot.position = {-1, 3.5, -3.2};
        spot.direction = {0.2, -1, 0.3};
        spot.outerAngleDeg = 35;
        doc.resetScene(std::move(s), {});
        doc.selection().setSelectedLights({3});
        InspectorView iv(&doc);
        iv.resize(640, 480);
        iv.show();
        QVERIFY(QTest::qWaitForWindowExposed(&iv));
        // From behind the column (the column between the eye and the apex).
        vtkCamera* cam = iv.renderer()->GetActiveCamera();
        cam->SetFocalPoint(-1, 3, -3);
        cam->SetPosition(1, 7, 16);
        cam->SetViewUp(0, 1, 0);
        iv.renderer()->ResetCameraClippingRange();
        iv.renderNow();
        QTest::qWait(50);
        iv.renderNow();
        const Comparison c = compareWithBaseline(iv.grabFramebuffer(), "inspector_spot_handles");
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));
    }

    // Difference mode (issue 7): |culled - all| of the shading pass drawn 1:1
    // in the letterboxed viewport (the largest error white), the grey legend
    // from 0 to that error, the caption with the image error, and the tile
    // grid and selected tile over the picture. 2.5d with 4 cells at tile 16:
    // the lights' cut-off leaves a visible error at the sphere edges.
    void differenceMode() {
        Document doc;
        const auto run = cullFixedScene(doc, lc::Algorithm::TwoPointFiveD, 4, true);
        QVERIFY(run);
        QVERIFY(run->truth.metrics.imageMaxError > 0); // the picture is not black
        doc.selection().setSelectedTile(int(run->result.grid.tileIndex(9, 6)));

        CameraView cv(&doc);
        cv.resize(720, 360);
        cv.setImageMode(CameraView::ImageMode::Difference);
        cv.show();
        QVERIFY(QTest::qWaitForWindowExposed(&cv));
        QVERIFY(cv.shownImage());
        cv.renderNow();
        QTest::qWait(50);
        cv.renderNow();
        const Comparison c =
            compareWithBaseline(cv.grabFramebuffer(), "camera_difference", tileRegions(cv, run->result.grid));
        QVERIFY2(c.ok, qPrintable(c.message));
        qInfo("%s", qPrintable(c.message));
    }
};

LC_STUDIO_TEST_MAIN(RenderTest)
#include "test_views.moc"
