// The Explain panel as a user reaches it: click a tile in the camera view's
// place (the document's tile selection), pick a light in the scene tree, and
// the panel shows lc::explainLight's explanation of that light in that list;
// a light the list lacks but pixels need is shown MISSING, in red.

#include "studio_test_support.hpp"

#include "document/document.hpp"
#include "panels/explain_panel.hpp"
#include "window/main_window.hpp"
#include "views/camera_view.hpp"
#include "views/inspector_view.hpp"
#include "views/overlay_actors.hpp"
#include "panels/tile_inspector.hpp"
#include "panels/scene_tree.hpp"

#include "culling/diagnostics/explain.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/diagnostics/overlays.hpp"

#include <vtkCamera.h>
#include <vtkPolyData.h>
#include <vtkRenderer.h>

#include <QAction>
#include <optional>
#include <QDir>
#include <QElapsedTimer>
#include <QComboBox>
#include <QLabel>
#include <QLineEdit>
#include <QSortFilterProxyModel>
#include <QFileInfo>
#include <QPlainTextEdit>
#include <QScrollBar>
#include <QTableView>
#include <QItemSelectionModel>

#include <set>
#include <QUndoStack>

using namespace lcui;

class ExplainPanelTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() const { return w_->document(); }
    // The tile whose list is longest in the shown run (the first of them).
    std::uint32_t busiestTile() const {
        const lc::CullResult& r = doc()->runs().runOutput()->result;
        std::uint32_t tile = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t)
            if (r.listCount[t] > r.listCount[tile]) tile = t;
        return tile;
    }

    bool waitTruth(quint64 generation) { return lctest::waitRun(*w_, generation, true); }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(w_->setParamFromUi("width", "320"));
        QVERIFY(w_->setParamFromUi("height", "180"));
        doc()->undoStack()->clear();
        QVERIFY(waitTruth(w_->runCulling()));
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    // The inspector's highlighted row follows the current light, wherever it
    // is chosen: a double-clicked row gives way to a light picked in the
    // scene tree (or the 3D view).
    void theHighlightedRowFollowsTheCurrentLight() {
        auto run = doc()->runs().runOutput();
        const std::uint32_t tile = busiestTile();
        doc()->selection().setSelectedTile(int(tile));
        TileInspector* ti = w_->tileInspector();
        QVERIFY(ti->proxy()->rowCount() >= 2);
        auto selectedLights = [&] {
            std::set<int> lights;
            for (const QModelIndex& i : ti->table()->selectionModel()->selectedRows())
                lights.insert(ti->proxy()->index(i.row(), TileLightsModel::ColLight).data().toInt());
            return lights;
        };
        const int a = ti->proxy()->index(0, TileLightsModel::ColLight).data().toInt();
        const int b = ti->proxy()->index(1, TileLightsModel::ColLight).data().toInt();
        const QRect rowA = ti->table()->visualRect(ti->proxy()->index(0, TileLightsModel::ColName));
        QTest::mouseClick(ti->table()->viewport(), Qt::LeftButton, {}, rowA.center());
        QTest::mouseDClick(ti->table()->viewport(), Qt::LeftButton, {}, rowA.center());
        QCOMPARE(doc()->selection().currentLight(), a);
        QCOMPARE(selectedLights(), std::set<int>{a});
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(b)); // as a click in the tree
        QCOMPARE(doc()->selection().currentLight(), b);
        QCOMPARE(selectedLights(), std::set<int>{b});
        // A light the tile's lists do not hold: no row stays highlighted.
        int other = -1;
        for (int i = 0; i < int(doc()->scene().lights.size()) && other < 0; ++i) {
            bool listed = false;
            for (int r = 0; r < ti->model()->rowCount(); ++r)
                listed = listed || int(ti->model()->rows()[std::size_t(r)].light) == i;
            if (!listed) other = i;
        }
        QVERIFY(other >= 0);
        doc()->selection().setSelectedLights({other});
        QVERIFY(selectedLights().empty());
    }

    // While a Live edit's lists wait for their ground truth, the panel says
    // so; it does not ask for a tile and a light already selected.
    void aRunWithoutTruthYetIsWaitedFor() {
        doc()->selection().setSelectedTile(0);
        doc()->selection().setSelectedLights({0});
        ExplainPanel* panel = w_->explainPanel();
        auto* verdict = panel->findChild<QLabel*>("explainVerdict");
        QVERIFY(panel->explanation());
        auto listsOnly = std::make_shared<lc::RunOutput>(*doc()->runs().runOutput());
        listsOnly->truthComputed = false;
        listsOnly->truth = {};
        QVERIFY(doc()->runs().setRunOutput(listsOnly, doc()->runs().runGeneration() + 1));
        QVERIFY(!panel->explanation());
        QVERIFY2(verdict->text().startsWith("Waiting for the ground truth"), qPrintable(verdict->text()));
        doc()->selection().setSelectedTile(-1);
        QVERIFY2(verdict->text().startsWith("Select a tile"), qPrintable(verdict->text()));
    }

    void explainsTheSelectedLightInTheSelectedTile() {
        ExplainPanel* panel = w_->explainPanel();
        QVERIFY(panel);
        QVERIFY(!panel->explanation()); // nothing selected yet: a hint
        auto run = doc()->runs().runOutput();
        // The busiest tile and a light listed there, chosen as a user would:
        // the tile in the camera view, the light in the scene tree.
        const std::uint32_t tile = busiestTile();
        const std::uint32_t light = run->result.lightIndices[run->result.listOffset[tile]];
        doc()->selection().setSelectedTile(int(tile));
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(light)));
        QVERIFY(panel->explanation());
        const lc::Explanation expect =
            lc::explainLight(*run, lc::Projection(doc()->scene().camera), tile, light);
        QCOMPARE(panel->explanation()->text(), expect.text());
        QCOMPARE(panel->explanation()->listed, true);
        QVERIFY(panel->textView()->toPlainText().contains("side plane left"));
        auto* verdict = panel->findChild<QLabel*>("explainVerdict");
        QCOMPARE(verdict->text(), QString::fromStdString(expect.verdict));

        // A light far from the tile: rejected, and the panel says by what.
        std::uint32_t far = 0;
        bool farFound = false;
        for (std::uint32_t i = 0; i < run->lights.size(); ++i) {
            const auto b = run->result.lightIndices.begin() + run->result.listOffset[tile];
            if (!std::binary_search(b, b + run->result.listCount[tile], i)) {
                far = i, farFound = true;
                break;
            }
        }
        QVERIFY2(farFound, "the busiest tile lists every light: no rejected light to explain");
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(far)));
        QVERIFY(panel->explanation());
        QCOMPARE(panel->explanation()->listed, false);
        QVERIFY2(verdict->text().contains("the first test to reject it:"), qPrintable(verdict->text()));
        QVERIFY(panel->textView()->toPlainText().contains("FAIL"));
        // Read at the default layout without scrolling sideways: the numbers
        // at the ends of the lines wrap into the dock.
        QTRY_COMPARE(panel->textView()->horizontalScrollBar()->maximum(), 0);
        // For a person to look at (docs/STUDIO.md): the window with the panel.
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(light)));
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(w_->grabWindow().save(LC_RENDER_OUT_DIR "/explain_panel.png"));
    }

    // Explain in 3D: the plane that decided and the pixel that matters, drawn
    // where the explanation puts them.
    void explainMarkersIn3D() {
        auto run = doc()->runs().runOutput();
        const lc::Projection proj(doc()->scene().camera);
        const glm::dmat4 world = lc::worldFromView(doc()->scene().camera);
        auto toWorld = [&](const glm::dvec3& v) { return glm::dvec3(world * glm::dvec4(v, 1.0)); };
        auto point = [](vtkPolyData* pd, vtkIdType i) {
            double p[3];
            pd->GetPoint(i, p);
            return glm::dvec3(p[0], p[1], p[2]);
        };
        auto near = [](const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b) <= 1e-6 * (1 + glm::length(a)); };
        // A tile with a false positive (listed, no pixel needs it) and a needed light.
        std::uint32_t tile = 0, fpLight = 0, neededLight = 0;
        bool found = false;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount() && !found; ++t) {
            int fp = -1, needed = -1;
            for (const auto& row : lc::tileLightRows(*run, proj, t, -1)) {
                if (row.verdict == lc::Verdict::FalsePositive && fp < 0) fp = int(row.light);
                if (row.verdict == lc::Verdict::Needed && needed < 0) needed = int(row.light);
            }
            if (fp >= 0 && needed >= 0) tile = t, fpLight = std::uint32_t(fp), neededLight = std::uint32_t(needed), found = true;
        }
        QVERIFY(found);
        doc()->selection().setSelectedTile(int(tile));
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(fpLight)));
        InspectorOverlays* ov = w_->inspectorView()->overlays();
        QVERIFY(ov->explanation());
        QCOMPARE(ov->explanation()->text(), w_->explainPanel()->explanation()->text());
        const lc::Explanation& e = *ov->explanation();
        QVERIFY(e.listed && e.pixelsNeeding == 0 && e.nearestDistance >= 0);
        // Every plane kept it: the one drawn is the closest to rejecting it.
        QVERIFY(e.decisivePlane >= 0 && e.decisiveMargin >= 0);
        const auto face = lc::chunkFace(e.chunkCorners, e.decisivePlane);
        const glm::dvec3 mid = 0.25 * (face[0] + face[1] + face[2] + face[3]);
        QCOMPARE(ov->explainPlane()->GetNumberOfPoints(), vtkIdType(4));
        for (int i = 0; i < 4; ++i)
            QVERIFY(near(point(ov->explainPlane(), i),
                         toWorld(mid + InspectorOverlays::kExplainPlaneScale * (face[std::size_t(i)] - mid))));
        // The nearest pixel and the nearest point of the light's sphere,
        // nearestDistance apart.
        QCOMPARE(ov->explainPixel()->GetNumberOfPoints(), vtkIdType(2));
        QCOMPARE(ov->explainPixel()->GetNumberOfLines(), vtkIdType(1));
        const glm::dvec3 px = point(ov->explainPixel(), 0), onSphere = point(ov->explainPixel(), 1);
        QVERIFY(near(px, toWorld(e.nearestPosition)));
        const double r = run->lights.radii[fpLight];
        QVERIFY(std::abs(glm::length(onSphere - toWorld(run->lights.centers[fpLight])) - r) <= 1e-6 * r);
        QVERIFY(std::abs(glm::length(px - onSphere) - e.nearestDistance) <= 1e-6 * (1 + r));
        w_->action("actionFrameSelected")->trigger();
        QTest::qWait(500);
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(w_->grabWindow().save(LC_RENDER_OUT_DIR "/explain_markers.png")); // to look at

        // A needed light: one marker, at a pixel inside its sphere.
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(neededLight)));
        QVERIFY(ov->explanation() && ov->explanation()->pixelsNeeding > 0);
        QCOMPARE(ov->explainPixel()->GetNumberOfPoints(), vtkIdType(1));
        QVERIFY(glm::length(point(ov->explainPixel(), 0) - toWorld(run->lights.centers[neededLight])) <=
                run->lights.radii[neededLight] * (1 + 1e-9));

        // A light the tile's planes reject: the plane drawn is one that failed.
        // Such a light must exist (asserted: the check below is the point).
        int rejected = -1;
        for (std::uint32_t i = 0; i < run->lights.size() && rejected < 0; ++i) {
            const auto ex = lc::explainLight(*run, proj, tile, i);
            if (!ex.testsPass && ex.decisiveMargin < 0) rejected = int(i);
        }
        QVERIFY2(rejected >= 0, "no light of the scene is rejected by a plane of this tile");
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(rejected));
        QVERIFY(ov->explanation());
        QVERIFY(!ov->explanation()->listed);
        QVERIFY(ov->explanation()->decisiveMargin < 0);
        {
            const std::string failed = lc::chunkPlaneName(ov->explanation()->decisivePlane);
            bool stepFailed = false;
            for (const auto& st : ov->explanation()->steps) stepFailed = stepFailed || (st.test == failed && !st.passed);
            QVERIFY2(stepFailed, failed.c_str());
            // The marker drawn is that plane's face, not the kept light's.
            const auto face = lc::chunkFace(ov->explanation()->chunkCorners, ov->explanation()->decisivePlane);
            const glm::dvec3 mid = 0.25 * (face[0] + face[1] + face[2] + face[3]);
            QCOMPARE(ov->explainPlane()->GetNumberOfPoints(), vtkIdType(4));
            for (int i = 0; i < 4; ++i)
                QVERIFY(near(point(ov->explainPlane(), i),
                             toWorld(mid + InspectorOverlays::kExplainPlaneScale * (face[std::size_t(i)] - mid))));
        }

        // The View > Overlays toggle removes both.
        w_->action("actionOverlayExplain")->trigger();
        QCOMPARE(ov->explainPlane()->GetNumberOfCells(), vtkIdType(0));
        QCOMPARE(ov->explainPixel()->GetNumberOfCells(), vtkIdType(0));
    }

    // F flies the inspector to the selected tile's frustum: afterwards all its
    // corners project inside the view. C looks through the culling camera.
    void frameSelectedAndLookThrough() {
        auto run = doc()->runs().runOutput();
        const lc::Projection proj(doc()->scene().camera);
        std::uint32_t tile = run->result.grid.tileIndex(7, 5);
        auto chunk = lc::tileFrustum(run->result, proj, run->lights, tile);
        for (std::uint32_t t = 0; !chunk && t < run->result.grid.tileCount(); ++t)
            if ((chunk = lc::tileFrustum(run->result, proj, run->lights, t))) tile = t;
        QVERIFY(chunk);
        doc()->selection().setSelectedTile(int(tile));
        InspectorView* iv = w_->inspectorView();
        vtkRenderer* ren = iv->renderer();
        const glm::dmat4 world = lc::worldFromView(doc()->scene().camera);
        // A view-space point in the inspector's display coordinates (device
        // pixels, y up; z the depth in [0, 1]).
        auto display = [&](const glm::dvec3& viewPoint) {
            const glm::dvec3 wpt = glm::dvec3(world * glm::dvec4(viewPoint, 1.0));
            ren->SetWorldPoint(wpt.x, wpt.y, wpt.z, 1.0);
            ren->WorldToDisplay();
            double d[3];
            ren->GetDisplayPoint(d);
            return glm::dvec3(d[0], d[1], d[2]);
        };
        auto cornersInside = [&] {
            int inside = 0;
            const int* size = ren->GetSize();
            for (const glm::dvec3& v : chunk->corners) {
                const glm::dvec3 d = display(v);
                inside += d.x >= 0 && d.x <= size[0] && d.y >= 0 && d.y <= size[1] && d.z >= 0 && d.z <= 1;
            }
            return inside;
        };
        // Start from a view where the tile is a sliver far away.
        iv->flyTo({0, 1000, 0}, 1.0, 0);
        QVERIFY(cornersInside() < 8);
        w_->action("actionFrameSelected")->trigger();
        QTest::qWait(500); // the flight takes 300 ms
        QCOMPARE(cornersInside(), 8);
        // The frustum fills the view: its projected extent spans a good part of it.
        double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
        for (const glm::dvec3& v : chunk->corners) {
            const glm::dvec3 d = display(v);
            for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], d[k]), hi[k] = std::max(hi[k], d[k]);
        }
        const int* size = ren->GetSize();
        QVERIFY2(std::max((hi[0] - lo[0]) / size[0], (hi[1] - lo[1]) / size[1]) > 0.5, "the frustum does not fill the view");
        QVERIFY(w_->grabWindow().save(LC_RENDER_OUT_DIR "/framed_tile.png")); // to look at

        w_->action("actionLookThrough")->trigger();
        // Pick in 3D: through the culling camera, a click inside the selected
        // tile enters its nearest cell first; with every tile's frustum drawn
        // and no cells, a click on another tile selects that tile.
        auto displayOf = [&](const glm::dvec3& viewPoint) { // as a widget position (logical px, y down)
            const glm::dvec3 d = display(viewPoint);
            const double dpr = iv->devicePixelRatioF();
            return QPoint(int(d.x / dpr), int(iv->height() - 1 - d.y / dpr));
        };
        auto centreOf = [](const lc::FrustumChunk& c) {
            glm::dvec3 m(0.0);
            for (const glm::dvec3& v : c.corners) m += v;
            return m / 8.0;
        };
        int pickedTile = -1, pickedCell = -1;
        QVERIFY(iv->pickChunk(displayOf(centreOf(*chunk)), &pickedTile, &pickedCell));
        QCOMPARE(pickedTile, int(tile));
        QCOMPARE(pickedCell, 0);
        OverlayOptions ov = doc()->viewOptions().overlays();
        ov.cells = false;
        ov.allTileFrustums = true;
        doc()->viewOptions().setOverlays(ov);
        std::uint32_t other = tile;
        std::optional<lc::FrustumChunk> otherChunk;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount() && !otherChunk; ++t)
            if (t != tile && t % run->result.grid.tilesX > 2 && t / run->result.grid.tilesX > 2)
                if ((otherChunk = lc::tileFrustum(run->result, proj, run->lights, t))) other = t;
        QVERIFY(otherChunk);
        QVERIFY(iv->pickChunk(displayOf(centreOf(*otherChunk)), &pickedTile, &pickedCell));
        QCOMPARE(pickedTile, int(other));
        QCOMPARE(pickedCell, -1);
        double pos[3];
        ren->GetActiveCamera()->GetPosition(pos);
        const glm::dvec3 cp = doc()->scene().camera.position;
        QVERIFY(glm::length(glm::dvec3(pos[0], pos[1], pos[2]) - cp) < 1e-9);
        QCOMPARE(ren->GetActiveCamera()->GetViewAngle(), doc()->scene().camera.fovYDeg);
    }

    // Readable at a glance: a tile's hover tooltip, the tile inspector's
    // verdict filter and column sort, the scene tree's filter and orders.
    void tooltipsFiltersAndSorting() {
        auto run = doc()->runs().runOutput();
        const std::uint32_t tile = busiestTile();
        CameraView* cv = w_->cameraView();
        const QString tip = cv->tileTooltip(int(tile));
        const std::uint32_t tx = tile % run->result.grid.tilesX, ty = tile / run->result.grid.tilesX;
        QVERIFY2(tip.startsWith(QString("tile %1,%2: list of %3 lights").arg(tx).arg(ty).arg(run->result.listCount[tile])),
                 qPrintable(tip));
        QVERIFY2(tip.contains("view depth") && tip.contains("efficiency"), qPrintable(tip));
        // The tooltip of the tile under a widget position is that tile's.
        const QPoint centre = cv->rect().center();
        QCOMPARE(cv->tileTooltip(cv->tileAtWidgetPos(centre)).isEmpty(), cv->tileAtWidgetPos(centre) < 0);

        doc()->selection().setSelectedTile(int(tile));
        TileInspector* ti = w_->tileInspector();
        const int all = ti->proxy()->rowCount();
        int fp = 0;
        for (const auto& r : ti->model()->rows()) fp += r.verdict == lc::Verdict::FalsePositive;
        QVERIFY(fp > 0 && fp < all);
        ti->verdictFilter()->setCurrentIndex(ti->verdictFilter()->findData(QStringLiteral("false positive")));
        QCOMPARE(ti->proxy()->rowCount(), fp);
        for (int r = 0; r < ti->proxy()->rowCount(); ++r)
            QCOMPARE(ti->proxy()->index(r, TileLightsModel::ColVerdict).data().toString(), QString("false positive"));
        ti->verdictFilter()->setCurrentIndex(0);
        QCOMPARE(ti->proxy()->rowCount(), all);
        // Sorting by pixels needing the light, most first (a header click).
        ti->proxy()->sort(TileLightsModel::ColPixels, Qt::DescendingOrder);
        for (int r = 1; r < ti->proxy()->rowCount(); ++r)
            QVERIFY(ti->proxy()->index(r - 1, TileLightsModel::ColPixels).data().toInt() >=
                    ti->proxy()->index(r, TileLightsModel::ColPixels).data().toInt());
        // By radius: by the number, not its text (10 after 9), shown to 4 digits.
        ti->proxy()->sort(TileLightsModel::ColRadius, Qt::AscendingOrder);
        for (int r = 1; r < ti->proxy()->rowCount(); ++r)
            QVERIFY(ti->proxy()->index(r - 1, TileLightsModel::ColRadius).data(Qt::EditRole).toDouble() <=
                    ti->proxy()->index(r, TileLightsModel::ColRadius).data(Qt::EditRole).toDouble());
        QVERIFY(ti->proxy()->index(0, TileLightsModel::ColRadius).data().toString().size() <= 6);
        // One list per tile: no list column repeating the tile's index.
        QCOMPARE(run->result.listsPerTile, 1u);
        QVERIFY(ti->findChild<QTableView*>()->isColumnHidden(TileLightsModel::ColList));

        // The scene tree: filter by name, then order by radius.
        auto* filter = w_->findChild<QLineEdit*>("sceneFilter");
        QVERIFY(filter);
        QTest::keyClicks(filter, "light_12");
        SceneTree* tree = w_->sceneTree();
        int shown = 0;
        const QModelIndex lightsGroup = tree->lightIndex(0).parent();
        for (int row = 0; row < int(doc()->scene().lights.size()); ++row)
            if (!tree->isRowHidden(row, lightsGroup)) {
                ++shown;
                QVERIFY(tree->sceneModel()->itemFromIndex(tree->sceneModel()->index(row, 0, lightsGroup))->text().contains("light_12"));
            }
        QCOMPARE(shown, 11); // light_12 and light_120..light_129
        filter->clear();
        auto* sort = w_->findChild<QComboBox*>("sceneSort");
        sort->setCurrentIndex(sort->findData(int(SceneTree::LightSort::Radius)));
        const std::vector<int> order = tree->lightOrder();
        QCOMPARE(order.size(), doc()->scene().lights.size());
        for (std::size_t k = 1; k < order.size(); ++k)
            QVERIFY(doc()->scene().lights[std::size_t(order[k - 1])].radius() >= doc()->scene().lights[std::size_t(order[k])].radius());
        // Selection still maps rows to lights after sorting.
        tree->setCurrentIndex(tree->lightIndex(order[0]));
        QCOMPARE(doc()->selection().currentLight(), order[0]);
        sort->setCurrentIndex(sort->findData(int(SceneTree::LightSort::TilesReached)));
        const std::vector<int> byTiles = tree->lightOrder();
        auto tilesOf = [&](int light) { return lc::tilesHoldingLight(run->result, std::uint32_t(light)).size(); };
        for (std::size_t k = 1; k < byTiles.size(); k += 37) QVERIFY(tilesOf(byTiles[k - 1]) >= tilesOf(byTiles[k]));
    }

    // An edit with Live off leaves the last run describing another scene: a
    // deleted light shifts every later index, so its rows and verdicts would
    // land on other lights. The inspector, Explain and the export say so
    // until the next run; a run of the edited scene brings them back.
    void anEditLeavesTheRunStaleUntilTheNextRun() {
        auto run = doc()->runs().runOutput();
        const std::uint32_t tile = busiestTile();
        doc()->selection().setSelectedTile(int(tile));
        TileInspector* ti = w_->tileInspector();
        QVERIFY(ti->model()->rows().size() >= 2);
        const int second = int(ti->model()->rows()[1].light);
        doc()->selection().setSelectedLights({second});
        ExplainPanel* panel = w_->explainPanel();
        QVERIFY(panel->explanation());
        QVERIFY(!doc()->runs().runIsStale());

        doc()->deleteLights({int(ti->model()->rows()[0].light)}); // an earlier light: `second` moves down one
        QVERIFY(doc()->runs().runIsStale());
        QVERIFY(ti->model()->rows().empty());
        QVERIFY2(ti->summaryText().contains("changed since the last run"), qPrintable(ti->summaryText()));
        QVERIFY(!panel->explanation());
        auto* verdict = panel->findChild<QLabel*>("explainVerdict");
        QVERIFY2(verdict->text().contains("changed since the last run"), qPrintable(verdict->text()));
        QVERIFY(!w_->inspectorView()->overlays()->explanation());
        QDir().mkpath(LC_RENDER_OUT_DIR); // for a person to look at: the stale state
        QVERIFY(w_->grabWindow().save(LC_RENDER_OUT_DIR "/stale_run.png"));
        QString refused;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { refused = m; };
        const QString dir = QDir::tempPath() + "/lightcull-stale-export";
        QDir(dir).removeRecursively();
        QVERIFY(!w_->exportDiagnostics(dir));
        QVERIFY2(refused.contains("press F5"), qPrintable(refused));
        QVERIFY(!QFileInfo::exists(dir + "/summary.json"));

        // The next run is of the edited scene: the same light, one index lower.
        QVERIFY(waitTruth(w_->runCulling()));
        QVERIFY(!doc()->runs().runIsStale());
        doc()->selection().setSelectedLights({second - 1});
        QVERIFY(panel->explanation());
        const lc::Explanation expect = lc::explainLight(*doc()->runs().runOutput(), lc::Projection(doc()->scene().camera),
                                                        tile, std::uint32_t(second - 1));
        QCOMPARE(panel->explanation()->text(), expect.text());
        QVERIFY(!ti->model()->rows().empty());

        // Undo is an edit too; with Live on an edit is never stale (its run
        // is asked for at once), and a run that fails leaves it stale.
        doc()->undoStack()->undo();
        QVERIFY(doc()->runs().runIsStale());
        w_->setLive(true); // asks for a run of the scene as it is
        QVERIFY(!doc()->runs().runIsStale());
        QVERIFY(waitTruth(doc()->runs().runGeneration() + 1));
        QVERIFY(!ti->model()->rows().empty());
        // A Live edit's run is asked for before anything hears of the edit:
        // the inspector keeps its rows until the new ones come (no flicker).
        QSignalSpy wentStale(&doc()->runs(), &RunState::runWentStale);
        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.5, 0, 0), doc()->newDragId());
        QVERIFY(!doc()->runs().runIsStale());
        QVERIFY(wentStale.isEmpty());
        QVERIFY(!ti->model()->rows().empty());
        w_->setLive(false);
        QVERIFY(waitTruth(w_->runCulling()));
        lc::Camera bad = doc()->scene().camera;
        bad.target = bad.position;
        doc()->setCamera(bad);
        QVERIFY(doc()->runs().runIsStale());
        const quint64 failing = w_->runCulling();
        QVERIFY(!doc()->runs().runIsStale()); // on its way
        QVERIFY(!lctest::waitRun(*w_, failing));
        QVERIFY(doc()->runs().runIsStale());
        QVERIFY(wentStale.size() >= 2); // the camera edit, then the failed run
    }

    // halfz and clustered tiles hold several lists: a tile inspector row
    // explains its own list, and without a row or cell picked the panel takes
    // the first list that holds the light, never one that says otherwise.
    void aRowOfASeveralListTileExplainsItsOwnList() {
        for (const char* algo : {"halfz", "clustered"}) {
            QVERIFY(w_->setParamFromUi("algorithm", algo));
            QVERIFY(waitTruth(w_->runCulling()));
            auto run = doc()->runs().runOutput();
            const lc::Projection proj(doc()->scene().camera);
            const std::uint32_t per = run->result.listsPerTile;
            QVERIFY(per > 1);
            // A tile whose later list holds a light its first list lacks.
            std::uint32_t tile = 0;
            std::optional<lc::TileLightRow> later;
            for (std::uint32_t t = 0; t < run->result.grid.tileCount() && !later; ++t) {
                const auto rows = lc::tileLightRows(*run, proj, t, -1);
                for (const auto& r : rows) {
                    bool inFirst = false;
                    for (const auto& q : rows) inFirst = inFirst || (q.light == r.light && q.list == t * per);
                    if (r.list > t * per && r.verdict != lc::Verdict::Missing && !inFirst) {
                        tile = t;
                        later = r;
                        break;
                    }
                }
            }
            QVERIFY2(later, algo);
            doc()->selection().setSelectedTile(int(tile));
            TileInspector* ti = w_->tileInspector();
            int row = -1;
            for (int r = 0; r < ti->proxy()->rowCount(); ++r) {
                const auto& m = ti->model()->rows()[std::size_t(ti->proxy()->mapToSource(ti->proxy()->index(r, 0)).row())];
                if (m.list == later->list && m.light == later->light) row = r;
            }
            QVERIFY(row >= 0);
            QApplication::processEvents(); // the table lays its new rows out
            ti->table()->scrollTo(ti->proxy()->index(row, 0));
            QApplication::processEvents();
            QVERIFY(ti->table()->viewport()->rect().contains(ti->table()->visualRect(ti->proxy()->index(row, 0)).center()));
            // A press first: Qt Test's double click alone has no pressed index.
            const QPoint at = ti->table()->visualRect(ti->proxy()->index(row, 0)).center();
            QTest::mouseClick(ti->table()->viewport(), Qt::LeftButton, {}, at);
            QTest::mouseDClick(ti->table()->viewport(), Qt::LeftButton, {}, at);
            QCOMPARE(doc()->selection().currentLight(), int(later->light));
            // The answer shows without scrolling: light, name, verdict, pixels.
            for (int c : {TileLightsModel::ColLight, TileLightsModel::ColName, TileLightsModel::ColVerdict,
                          TileLightsModel::ColPixels})
                QVERIFY2(ti->table()->columnViewportPosition(c) + ti->table()->columnWidth(c) / 2 <
                             ti->table()->viewport()->width(),
                         qPrintable(QString("column %1").arg(c)));
            ExplainPanel* panel = w_->explainPanel();
            QVERIFY(panel->explanation());
            const lc::Explanation expect = lc::explainLight(*run, proj, later->list, later->light);
            QCOMPARE(panel->explanation()->text(), expect.text());
            QVERIFY(panel->explanation()->listed);
            // The same light chosen in the scene tree: its first listing list.
            doc()->selection().setSelectedTile(-1);
            doc()->selection().setSelectedTile(int(tile));
            w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(later->light)));
            QVERIFY(panel->explanation());
            QVERIFY2(panel->explanation()->listed, algo);
        }
    }
};

LC_STUDIO_TEST_MAIN(ExplainPanelTest)
#include "test_explain_panel.moc"
