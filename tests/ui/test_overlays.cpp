// Inspection overlays in the studio (Qt Test under Xvfb, real widgets, CPU
// backend): the tile inspector's lists and ground-truth verdicts, a missing
// light shown in red, cell selection, reverse look-up in both views, heat-map
// modes, overlay toggles and the all-tiles wireframe; and overlays.vtm from
// File > Export diagnostics and from the CLI's `run --out`, read back with
// VTK's vtkXMLMultiBlockDataReader and checked block by block against the run.

#include "studio_test_support.hpp"

#include "views/camera_view.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "window/main_window.hpp"
#include "views/overlay_actors.hpp"
#include "panels/tile_inspector.hpp"

#include "culling/diagnostics/overlays.hpp"
#include "culling/scene/scene_io.hpp"

#include <QDir>
#include <QAction>
#include <QBrush>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QProcess>
#include <QTableView>
#include <QUndoStack>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCellData.h>
#include <vtkCompositeDataSet.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkInformation.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkScalarBarActor.h>
#include <vtkXMLMultiBlockDataReader.h>

#include <bit>
#include <cmath>
#include <memory>
#include <set>

using namespace lcui;

namespace {


// Lists of tile t, straight from the CullResult arrays.
std::vector<std::uint32_t> listsOfTile(const lc::CullResult& r, std::uint32_t t) {
    std::vector<std::uint32_t> out;
    if (r.algorithm == lc::Algorithm::All) return {0};
    for (std::uint32_t s = 0; s < r.listsPerTile; ++s) out.push_back(t * r.listsPerTile + s);
    return out;
}
std::vector<int> lightsOfList(const lc::CullResult& r, std::uint32_t l) {
    std::vector<int> out;
    for (std::uint32_t k = 0; k < r.listCount[l]; ++k) out.push_back(int(r.lightIndices[r.listOffset[l] + k]));
    return out;
}

// Reads a multiblock file; any VTK error or warning fails the read.
struct VtmRead {
    vtkSmartPointer<vtkMultiBlockDataSet> blocks;
    int errors = 0;
};
VtmRead readVtm(const QString& path) {
    VtmRead out;
    vtkNew<vtkXMLMultiBlockDataReader> reader;
    vtkNew<vtkCallbackCommand> onError;
    onError->SetClientData(&out.errors);
    onError->SetCallback([](vtkObject*, unsigned long, void* count, void*) { ++*static_cast<int*>(count); });
    reader->AddObserver(vtkCommand::ErrorEvent, onError);
    reader->AddObserver(vtkCommand::WarningEvent, onError);
    reader->SetFileName(path.toUtf8().constData());
    reader->Update();
    out.blocks = vtkMultiBlockDataSet::SafeDownCast(reader->GetOutput());
    return out;
}

glm::dvec3 toWorld(const lc::Camera& c, const glm::dvec3& v) {
    return glm::dvec3(lc::worldFromView(c) * glm::dvec4(v, 1.0));
}

bool sameOrBothNaN(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

// Checks an overlays.vtm against the run it was written from.
void checkVtm(const QString& path, const lc::Scene& scene, const lc::RunOutput& run) {
    const VtmRead v = readVtm(path);
    QCOMPARE(v.errors, 0);
    QVERIFY(v.blocks);
    QCOMPARE(int(v.blocks->GetNumberOfBlocks()), 4);
    const char* names[4] = {"camera_frustum", "tile_frustums", "depth_cells", "light_spheres"};
    for (unsigned i = 0; i < 4; ++i) {
        QCOMPARE(QString(v.blocks->GetMetaData(i)->Get(vtkCompositeDataSet::NAME())), QString(names[i]));
        QVERIFY(vtkPolyData::SafeDownCast(v.blocks->GetBlock(i)));
    }
    const lc::CullResult& r = run.result;
    const lc::Camera& cam = scene.camera;
    const lc::Projection proj(cam);
    auto near = [](const glm::dvec3& a, const double* b) {
        return glm::length(a - glm::dvec3(b[0], b[1], b[2])) <= 1e-9 * (1 + glm::length(a));
    };

    // Camera frustum: 8 corners + the eye; 12 edges + 4 to the eye (perspective).
    auto* camPd = vtkPolyData::SafeDownCast(v.blocks->GetBlock(0));
    QCOMPARE(int(camPd->GetNumberOfPoints()), 9);
    QCOMPARE(int(camPd->GetNumberOfLines()), proj.orthographic() ? 12 : 16);
    QVERIFY(near(cam.position, camPd->GetPoint(8)));

    // Tile frustums: 6 quads per tile with a frustum, cell data per quad.
    auto* tiles = vtkPolyData::SafeDownCast(v.blocks->GetBlock(1));
    vtkDataArray* aTile = tiles->GetCellData()->GetArray("tile");
    vtkDataArray* aCount = tiles->GetCellData()->GetArray("count");
    vtkDataArray* aEff = tiles->GetCellData()->GetArray("efficiency");
    vtkDataArray* aFp = tiles->GetCellData()->GetArray("false_positives");
    QVERIFY(aTile && aCount && aEff && aFp);
    std::size_t withFrustum = 0;
    for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) withFrustum += lc::tileFrustum(r, proj, run.lights, t).has_value();
    QCOMPARE(std::size_t(tiles->GetNumberOfPolys()), 6 * withFrustum);
    const auto eff = lc::tileHeat(run, lc::HeatMode::Efficiency);
    std::size_t checkedCorners = 0;
    for (vtkIdType c = 0; c < tiles->GetNumberOfCells(); c += 6) {
        const auto t = std::uint32_t(aTile->GetTuple1(c));
        std::uint64_t entries = 0;
        for (std::uint32_t l : listsOfTile(r, t)) entries += r.listCount[l];
        QCOMPARE(std::uint64_t(aCount->GetTuple1(c)), entries);
        // A tile without geometry (naive draws its frustum) shades nothing:
        // efficiency 1 and no false positive, never NaN (only `all` has no
        // per-tile figures).
        const bool empty = !(r.tileDepthMin[t] <= r.tileDepthMax[t]) && r.algorithm != lc::Algorithm::All;
        QVERIFY(sameOrBothNaN(aEff->GetTuple1(c), empty ? 1.0 : eff[t]));
        if (r.algorithm != lc::Algorithm::All) {
            QVERIFY(!std::isnan(aEff->GetTuple1(c)));
            QVERIFY(!std::isnan(aFp->GetTuple1(c)));
        }
        // The near face's corners are the culling's frustum corners, in world space.
        const auto chunk = lc::tileFrustum(r, proj, run.lights, t);
        QVERIFY(chunk);
        vtkNew<vtkIdList> ids;
        tiles->GetCellPoints(c, ids);
        QCOMPARE(int(ids->GetNumberOfIds()), 4);
        for (int k = 0; k < 4; ++k) QVERIFY(near(toWorld(cam, chunk->corners[k]), tiles->GetPoint(ids->GetId(k))));
        ++checkedCorners;
    }
    QVERIFY(checkedCorners > 10);

    // Depth cells: occupancy per (tile, cell) as tileCells says, from cellMask.
    auto* cells = vtkPolyData::SafeDownCast(v.blocks->GetBlock(2));
    vtkDataArray* cTile = cells->GetCellData()->GetArray("tile");
    vtkDataArray* cCell = cells->GetCellData()->GetArray("cell");
    vtkDataArray* cOcc = cells->GetCellData()->GetArray("occupied");
    QVERIFY(cTile && cCell && cOcc);
    std::size_t occupied = 0;
    for (vtkIdType c = 0; c < cells->GetNumberOfCells(); c += 6) {
        const auto t = std::uint32_t(cTile->GetTuple1(c));
        const auto k = std::uint32_t(cCell->GetTuple1(c));
        const bool bit = (r.cellMask.at(t) >> k) & 1u;
        QCOMPARE(cOcc->GetTuple1(c) != 0, bit);
        occupied += bit;
    }
    std::size_t maskBits = 0;
    for (std::uint32_t m : r.cellMask) maskBits += std::size_t(std::popcount(m));
    QCOMPARE(occupied, maskBits); // every occupied cell is in the file

    // Light spheres: one vertex per light at its world position, index and radius.
    auto* spheres = vtkPolyData::SafeDownCast(v.blocks->GetBlock(3));
    QCOMPARE(std::size_t(spheres->GetNumberOfPoints()), run.lights.size());
    vtkDataArray* sIndex = spheres->GetPointData()->GetArray("index");
    vtkDataArray* sRadius = spheres->GetPointData()->GetArray("radius");
    QVERIFY(sIndex && sRadius);
    for (vtkIdType i = 0; i < spheres->GetNumberOfPoints(); ++i) {
        QCOMPARE(vtkIdType(sIndex->GetTuple1(i)), i);
        QCOMPARE(sRadius->GetTuple1(i), run.lights.radii[std::size_t(i)]);
        QVERIFY(near(scene.lights[std::size_t(i)].position, spheres->GetPoint(i)));
    }
}

} // namespace

class OverlaysTest : public QObject {
    Q_OBJECT

    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;

    Document* doc() { return w_->document(); }

    bool waitRun(quint64 generation) { return lctest::waitRun(*w_, generation); }

    void openSmall(const QString& algorithm = "2.5d", const QString& size = "320x180", const QString& tile = "16") {
        const QStringList wh = size.split('x');
        QVERIFY(lctest::openBuiltinWith(
            *w_, "atrium", {{"width", wh[0]}, {"height", wh[1]}, {"tile", tile}, {"algorithm", algorithm}}));
        QVERIFY(waitRun(w_->runCulling()));
    }

    // The tile with the most listed lights.
    std::uint32_t busiestTile() {
        const lc::CullResult& r = doc()->runs().runOutput()->result;
        std::uint32_t best = 0, bestCount = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
            std::uint32_t n = 0;
            for (std::uint32_t l : listsOfTile(r, t)) n += r.listCount[l];
            if (n > bestCount) best = t, bestCount = n;
        }
        return best;
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    }

    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    // Selecting a tile lists exactly its CullResult list, each light with the
    // pixels that need it (ground truth) and the right verdict; a light taken
    // out of the list shows up as MISSING, in red, in the dock and in 3D.
    void tileInspectorListsAndVerdicts() {
        openSmall();
        auto run = doc()->runs().runOutput();
        const lc::CullResult& r = run->result;
        const std::uint32_t t = busiestTile();
        doc()->selection().setSelectedTile(int(t));
        TileInspector* ti = w_->tileInspector();
        QCOMPARE(ti->listedLights(), lightsOfList(r, t));
        const lc::Projection proj(doc()->scene().camera);
        const auto needed = lc::pixelsNeedingLights(run->depth, proj, run->lights, r.grid, t);
        std::map<std::uint32_t, std::uint32_t> need(needed.begin(), needed.end());
        int nNeeded = 0, nFp = 0;
        QAbstractItemModel* m = ti->table()->model();
        QCOMPARE(m->rowCount(), int(r.listCount[t]));
        for (int row = 0; row < m->rowCount(); ++row) {
            const auto light = std::uint32_t(m->index(row, TileLightsModel::ColLight).data().toInt());
            const int pixels = m->index(row, TileLightsModel::ColPixels).data().toInt();
            const QString verdict = m->index(row, TileLightsModel::ColVerdict).data().toString();
            QCOMPARE(pixels, int(need.count(light) ? need[light] : 0));
            QCOMPARE(verdict, QString(pixels > 0 ? "needed" : "false positive"));
            QCOMPARE(m->index(row, TileLightsModel::ColName).data().toString(),
                     QString::fromStdString(doc()->scene().lights[light].name));
            (pixels > 0 ? nNeeded : nFp)++;
        }
        QVERIFY(nNeeded > 0);
        QVERIFY(ti->summaryText().contains(QString("%1 needed, %2 false positive, 0 missing").arg(nNeeded).arg(nFp)));
        // In 3D the listed lights are highlighted and the rest dimmed.
        InspectorOverlays* ov = w_->inspectorView()->overlays();
        QCOMPARE(ov->listedLights(), lightsOfList(r, t));
        QVERIFY(ov->missingLights().empty());
        QVERIFY(w_->inspectorView()->lightActor()->GetProperty()->GetOpacity() < 0.1);

        // Drop a needed light from the tile's list: a culling bug, shown red.
        auto broken = std::make_shared<lc::RunOutput>(*run);
        lc::CullResult& br = broken->result;
        int victim = -1;
        for (int row = 0; row < m->rowCount() && victim < 0; ++row)
            if (m->index(row, TileLightsModel::ColPixels).data().toInt() > 0)
                victim = m->index(row, TileLightsModel::ColLight).data().toInt();
        auto first = br.lightIndices.begin() + br.listOffset[t];
        auto it = std::find(first, first + br.listCount[t], std::uint32_t(victim));
        std::rotate(it, it + 1, first + br.listCount[t]);
        --br.listCount[t];
        QVERIFY(doc()->runs().setRunOutput(broken, doc()->runs().runGeneration() + 1));
        std::vector<int> expect = lightsOfList(r, t);
        expect.erase(std::find(expect.begin(), expect.end(), victim));
        QCOMPARE(ti->listedLights(), expect);
        const int last = m->rowCount() - 1;
        QCOMPARE(m->index(last, TileLightsModel::ColLight).data().toInt(), victim);
        QCOMPARE(m->index(last, TileLightsModel::ColVerdict).data().toString(), QString("MISSING"));
        QCOMPARE(m->index(last, TileLightsModel::ColPixels).data().toInt(), int(need[std::uint32_t(victim)]));
        QCOMPARE(m->index(last, 0).data(Qt::BackgroundRole).value<QBrush>().color().red(), 200);
        QVERIFY(ti->summaryText().contains("1 missing"));
        QCOMPARE(ov->missingLights(), std::vector<int>{victim});
    }

    // A cell of the selected tile: its pixels only; occupied cells filled,
    // every cell outlined; the current light's cell range.
    void cellsAndCellSelection() {
        openSmall();
        const auto run = doc()->runs().runOutput();
        const lc::CullResult& r = run->result;
        const std::uint32_t t = busiestTile();
        doc()->selection().setSelectedTile(int(t));
        InspectorOverlays* ov = w_->inspectorView()->overlays();
        const std::uint32_t mask = r.cellMask[t];
        QCOMPARE(int(ov->cellFill()->GetNumberOfPolys()), 6 * std::popcount(mask));
        QCOMPARE(int(ov->cellOutline()->GetNumberOfLines()), 12 * int(r.settings.cells));
        QCOMPARE(int(ov->tileSolid()->GetNumberOfPolys()), 6);

        // Pixels per light summed over the occupied cells equal the whole tile's.
        std::map<int, int> whole, byCell;
        TileInspector* ti = w_->tileInspector();
        for (const auto& row : ti->rows()) whole[int(row.light)] += int(row.pixelsNeeding);
        for (std::uint32_t k = 0; k < r.settings.cells; ++k) {
            doc()->selection().setSelectedCell(int(k));
            QVERIFY(ti->summaryText().contains(QString("cell %1").arg(k)));
            for (const auto& row : ti->rows()) byCell[int(row.light)] += int(row.pixelsNeeding);
            if ((mask >> k) & 1u) QCOMPARE(ti->listedLights(), lightsOfList(r, t)); // one list per 2.5d tile
        }
        QCOMPARE(byCell, whole);

        // The current light's cell range: the cells its depth interval overlaps.
        const int light = lightsOfList(r, t).front();
        doc()->selection().setSelectedLights({light});
        const double d = -run->lights.centers[std::size_t(light)].z, rad = run->lights.radii[std::size_t(light)];
        int spanned = 0;
        for (const auto& c : lc::tileCells(r, lc::Projection(doc()->scene().camera), t))
            spanned += d + rad >= c.chunk.depthMin && d - rad <= c.chunk.depthMax;
        QVERIFY(spanned > 0);
        QCOMPARE(int(ov->lightRange()->GetNumberOfLines()), 12 * spanned);

        // Toggles through the View > Overlays actions.
        w_->action("actionOverlayCells")->trigger();
        QVERIFY(!doc()->viewOptions().overlays().cells);
        QCOMPARE(int(ov->cellFill()->GetNumberOfCells()), 0);
        w_->action("actionOverlayTileFrustum")->trigger();
        QCOMPARE(int(ov->tileSolid()->GetNumberOfCells()), 0);
        w_->action("actionOverlayCells")->trigger();
        QCOMPARE(int(ov->cellFill()->GetNumberOfPolys()), 6 * std::popcount(mask));
    }

    // A Z-binned run: the toolbar's Bins sets the bin count; the selected
    // tile shows the bins its depth range spans as cells, and the current
    // light the slab of the camera frustum over its bins.
    void zbinBinsAndLightSlab() {
        openSmall("zbin");
        QVERIFY(w_->setParamFromUi("bins", "256"));
        QVERIFY(waitRun(w_->runCulling()));
        const auto run = doc()->runs().runOutput();
        const lc::CullResult& r = run->result;
        QVERIFY(r.algorithm == lc::Algorithm::ZBin);
        QCOMPARE(r.zbinLo.size(), std::size_t(256));
        const std::uint32_t t = busiestTile();
        doc()->selection().setSelectedTile(int(t));
        InspectorOverlays* ov = w_->inspectorView()->overlays();
        const lc::Projection proj(doc()->scene().camera);
        const auto cells = lc::tileCells(r, proj, t);
        const std::uint32_t span = r.zbinOf(r.tileDepthMax[t]) - r.zbinOf(r.tileDepthMin[t]) + 1;
        QCOMPARE(cells.size(), std::size_t(std::min(span, 32u)));
        QCOMPARE(int(ov->cellOutline()->GetNumberOfLines()), 12 * int(cells.size()));
        // The cells cover the tile's depth range, near to far, without gaps.
        QVERIFY(cells.front().chunk.depthMin <= r.tileDepthMin[t]);
        QVERIFY(cells.back().chunk.depthMax >= r.tileDepthMax[t]);
        for (std::size_t k = 1; k < cells.size(); ++k)
            QCOMPARE(cells[k].chunk.depthMin, cells[k - 1].chunk.depthMax);

        const int light = lightsOfList(r, t).front();
        doc()->selection().setSelectedLights({light});
        const auto slab = lc::zbinLightSlab(r, proj, run->lights, std::uint32_t(light));
        QVERIFY(slab);
        const double d = -run->lights.centers[std::size_t(light)].z, rad = run->lights.radii[std::size_t(light)];
        QVERIFY(slab->depthMin <= std::max(d - rad, r.zbinNear));
        QVERIFY(slab->depthMax >= std::min(d + rad, r.zbinFar));
        QVERIFY(slab->depthMax - slab->depthMin <= 2 * rad + 2 * (r.zbinFar - r.zbinNear) / 256 + 1e-9);
        QCOMPARE(int(ov->zbinSlab()->GetNumberOfPolys()), 6);
        QCOMPARE(int(ov->zbinSlab()->GetNumberOfLines()), 12);
        const glm::dmat4 world = lc::worldFromView(doc()->scene().camera);
        double p[3];
        ov->zbinSlab()->GetPoint(0, p);
        const glm::dvec3 c0 = glm::dvec3(world * glm::dvec4(slab->corners[0], 1.0));
        QVERIFY(glm::length(glm::dvec3(p[0], p[1], p[2]) - c0) <= 1e-6 * (1 + glm::length(c0)));
        w_->inspectorView()->renderNow();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(w_->grabWindow().save(LC_RENDER_OUT_DIR "/zbin_slab.png")); // to look at
        // Another algorithm: no slab.
        QVERIFY(w_->setParamFromUi("algorithm", "minmax"));
        QVERIFY(waitRun(w_->runCulling()));
        QCOMPARE(int(ov->zbinSlab()->GetNumberOfCells()), 0);
    }

    // Selecting a light outlines, in both views, exactly the tiles (and for
    // halfz the half-cells) whose lists hold it.
    void reverseLookupInBothViews() {
        for (const QString alg : {"2.5d", "halfz"}) {
            openSmall(alg);
            const lc::CullResult& r = doc()->runs().runOutput()->result;
            // A light held by several lists.
            int light = -1;
            std::set<int> expectTiles;
            std::vector<std::uint32_t> expectLists;
            for (std::size_t i = 0; i < doc()->scene().lights.size() && light < 0; ++i) {
                std::set<int> tiles;
                std::vector<std::uint32_t> lists;
                for (std::uint32_t l = 0; l < r.listCount.size(); ++l)
                    for (int x : lightsOfList(r, l))
                        if (x == int(i)) tiles.insert(int(l / r.listsPerTile)), lists.push_back(l);
                if (tiles.size() >= 3) light = int(i), expectTiles = tiles, expectLists = lists;
            }
            QVERIFY(light >= 0);
            doc()->selection().setSelectedLights({light});
            const auto& shown = w_->cameraView()->highlightedTiles();
            QCOMPARE(std::set<int>(shown.begin(), shown.end()), expectTiles);
            InspectorOverlays* ov = w_->inspectorView()->overlays();
            QCOMPARE(ov->reverseLists(), expectLists);
            QCOMPARE(int(ov->reverse()->GetNumberOfLines()), 12 * int(expectLists.size()));
            if (alg == "halfz") {
                doc()->selection().setSelectedTile(*expectTiles.begin());
                QCOMPARE(int(ov->splitQuad()->GetNumberOfPolys()), 1); // the split between the halves
            }
            w_->action("actionOverlayReverse")->trigger(); // off
            QVERIFY(w_->cameraView()->highlightedTiles().empty());
            QCOMPARE(int(ov->reverse()->GetNumberOfCells()), 0);
            w_->action("actionOverlayReverse")->trigger(); // on again for the next round
        }
    }

    // Heat-map modes: what the camera view shows per tile, from the ground
    // truth's per-list work.
    void heatMapModes() {
        openSmall("halfz");
        const auto run = doc()->runs().runOutput();
        const lc::CullResult& r = run->result;
        const auto& gt = run->truth;
        CameraView* cv = w_->cameraView();
        w_->action("actionHeat_false-positives")->trigger();
        QVERIFY(doc()->viewOptions().overlays().heat == lc::HeatMode::FalsePositives);
        // Two lines beside the image, one under it (CameraView::legendPlace).
        const QString sep = cv->legendPlace() == CameraView::LegendPlace::Below ? " " : "\n";
        QCOMPARE(QString(cv->legend()->GetTitle()), "false" + sep + "positives");
        double fpSum = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
            const double v = cv->shownHeat()[t];
            if (!(r.tileDepthMin[t] <= r.tileDepthMax[t])) {
                QVERIFY(std::isnan(v));
                continue;
            }
            const double w = double(gt.listShadingWork[2 * t] + gt.listShadingWork[2 * t + 1]);
            const double e = double(gt.listExactWork[2 * t] + gt.listExactWork[2 * t + 1]);
            QCOMPARE(v, w - e);
            fpSum += v;
        }
        QCOMPARE(fpSum, double(gt.metrics.shadingWork - gt.metrics.exactWork));
        w_->action("actionHeat_efficiency")->trigger();
        QCOMPARE(QString(cv->legend()->GetTitle()), "efficiency" + sep + "per tile");
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
            if (!(r.tileDepthMin[t] <= r.tileDepthMax[t])) continue;
            const double w = double(gt.listShadingWork[2 * t] + gt.listShadingWork[2 * t + 1]);
            const double e = double(gt.listExactWork[2 * t] + gt.listExactWork[2 * t + 1]);
            QCOMPARE(cv->shownHeat()[t], w > 0 ? e / w : 1.0);
        }
        w_->action("actionHeat_list-length")->trigger();
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t)
            if (r.tileDepthMin[t] <= r.tileDepthMax[t])
                QCOMPARE(cv->shownHeat()[t], double(std::max(r.listCount[2 * t], r.listCount[2 * t + 1])));
    }

    // Every tile's frustum as one wireframe actor: 12 lines per tile, list
    // length as cell scalars. 14,400 tiles (640x360 at 4 px): the frame time
    // is printed (a measurement, not an assertion).
    void allTileFrustumsIsOneActor() {
        openSmall("minmax", "640x360", "4");
        const lc::CullResult& r = doc()->runs().runOutput()->result;
        QCOMPARE(r.grid.tileCount(), 160u * 90u);
        InspectorView* iv = w_->inspectorView();
        auto frameMs = [iv] {
            iv->renderNow();
            QElapsedTimer timer;
            timer.start();
            for (int i = 0; i < 5; ++i) iv->renderWindow()->Render();
            return timer.elapsed() / 5.0;
        };
        const double withoutMs = frameMs();
        w_->action("actionOverlayAllTiles")->trigger();
        InspectorOverlays* ov = w_->inspectorView()->overlays();
        std::size_t withGeometry = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) withGeometry += r.tileDepthMin[t] <= r.tileDepthMax[t];
        QVERIFY(withGeometry > 10000);
        QCOMPARE(std::size_t(ov->allTiles()->GetNumberOfLines()), 12 * withGeometry);
        vtkDataArray* len = ov->allTiles()->GetCellData()->GetScalars();
        QVERIFY(len);
        QCOMPARE(QString(len->GetName()), QString("list_length"));
        QVERIFY(ov->allTilesActor()->GetVisibility());
        const double withMs = frameMs();
        qInfo("all tile frustums: %zu tiles, %.1f ms per frame (%.1f ms without them) at %dx%d (Xvfb, llvmpipe)",
              withGeometry, withMs, withoutMs, iv->width(), iv->height());
        w_->action("actionOverlayAllTiles")->trigger();
        QCOMPARE(int(ov->allTiles()->GetNumberOfCells()), 0);
        QVERIFY(!ov->allTilesActor()->GetVisibility());
    }

    // File > Export diagnostics: one atomic folder with the CLI's files,
    // overlays.vtm (read back with VTK) and both views' screenshots.
    void exportFromStudioReadsBackInVtk() {
        openSmall();
        doc()->selection().setSelectedTile(int(busiestTile()));
        const QString dir = tmp_.path() + "/studio-export";
        QVERIFY(lctest::exportAndWait(*w_, dir));
        for (const char* f : {"summary.json", "tiles.csv", "heatmap.png", "overlays.vtm", "camera_view.png",
                              "inspector_view.png"})
            QVERIFY2(QFileInfo(dir + "/" + f).isFile(), f);
        for (const char* f : {"camera_view.png", "inspector_view.png"}) {
            QImage img(dir + "/" + f);
            QVERIFY(!img.isNull());
            QSet<QRgb> colours;
            for (int y = 0; y < img.height(); y += 7)
                for (int x = 0; x < img.width(); x += 7) colours.insert(img.pixel(x, y));
            QVERIFY2(colours.size() > 20, f); // a real picture, not a blank frame
        }
        checkVtm(dir + "/overlays.vtm", doc()->scene(), *doc()->runs().runOutput());
        // No staging folder left beside it.
        QCOMPARE(QDir(tmp_.path()).entryList(QDir::AllEntries | QDir::NoDotAndDotDot | QDir::Hidden),
                 QStringList{"studio-export"});
    }

    // The CLI's `run --out` writes the same overlays.vtm through the same exporter.
    // (naive: with the frustums of tiles without geometry.)
    void cliRunOutWritesOverlaysVtm() {
        for (const lc::Algorithm a : {lc::Algorithm::Clustered, lc::Algorithm::Naive}) {
            const QString out = tmp_.path() + "/cli-export-" + lc::toString(a);
            QProcess cli;
            cli.start(LC_CLI_PATH, {"run", "--builtin", "atrium", "--width", "320", "--height", "180", "--tile", "16",
                                    "--algorithm", lc::toString(a), "--cells", "16", "--backend", "cpu",
                                    "--no-image-error", "--out", out});
            QVERIFY(cli.waitForFinished(lctest::kRunTimeoutMs));
            QVERIFY2(cli.exitCode() == 0, cli.readAllStandardError().constData());
            // The same run in-process, to check the file against.
            lc::Scene scene = lc::makeBuiltinScene("atrium");
            scene.camera.width = 320;
            scene.camera.height = 180;
            scene.camera.tileSize = 16;
            lc::CullSettings s;
            s.algorithm = a;
            s.cells = 16;
            auto backend = lc::makeBackend("cpu");
            lc::RunOptions opt;
            opt.truthOptions.imageError = false;
            const lc::RunOutput run = lc::runPipeline(scene, s, *backend, opt);
            checkVtm(out + "/overlays.vtm", scene, run);
        }
    }
};

LC_STUDIO_TEST_MAIN(OverlaysTest)
#include "test_overlays.moc"
