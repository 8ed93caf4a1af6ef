// The camera view's overlays: the heat map and tile grid of the shown run, the
// legend and caption, the tiles whose lists hold the current light, and the
// selected tile's outline (camera_view.hpp).
#include "views/camera_view.hpp"

#include "culling/custom/custom_cull.hpp"

#include "document/document.hpp"
#include "views/vtk_adapters.hpp"

#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/overlays.hpp"

#include <QHelpEvent>
#include <QMouseEvent>
#include <QWheelEvent>
#include <QTimer>
#include <QToolTip>
#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCoordinate.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkImageMapper.h>
#include <vtkImageMapper3D.h>
#include <vtkInteractorStyleUser.h>
#include <vtkLookupTable.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTransformPolyDataFilter.h>
#include <vtkUnsignedCharArray.h>
#include <QVTKInteractor.h>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace lcui {

void CameraView::updateOverlay() {
    const auto run = doc_->runs().runOutput();
    clearOverlay(heatData_);
    clearOverlay(gridData_);
    if (!run) {
        heatCaption_ = "no culling run yet (F5)";
        updateImage();
        updateLegendAndCaption();
        updateSelectedTile();
        scheduleRender();
        return;
    }
    const lc::TileGrid& g = run->result.grid;
    const double W = g.width, H = g.height;
    auto nx = [&](double px) { return px / W; };
    auto ny = [&](double py) { return 1.0 - py / H; }; // pixel rows go down, viewport y up

    // Tile corner lattice, clipped to the image (edge tiles are partial).
    vtkNew<vtkPoints> pts;
    auto cornerX = [&](std::uint32_t i) { return std::min<double>(double(i) * g.tileSize, W); };
    auto cornerY = [&](std::uint32_t j) { return std::min<double>(double(j) * g.tileSize, H); };
    for (std::uint32_t j = 0; j <= g.tilesY; ++j)
        for (std::uint32_t i = 0; i <= g.tilesX; ++i) pts->InsertNextPoint(nx(cornerX(i)), ny(cornerY(j)), 0);
    auto pid = [&](std::uint32_t i, std::uint32_t j) { return vtkIdType(j * (g.tilesX + 1) + i); };

    // Heat per tile in the chosen mode. List length and false positives run
    // blue (low) to red (high); efficiency red (0, all wasted) to blue (1).
    const lc::HeatMode mode = doc_->viewOptions().overlays().heat;
    shownHeat_ = lc::tileHeat(*run, mode);
    vtkNew<vtkCellArray> quads;
    vtkNew<vtkDoubleArray> values;
    values->SetName(lc::toString(mode));
    double maxHeat = 0;
    for (std::uint32_t ty = 0; ty < g.tilesY; ++ty)
        for (std::uint32_t tx = 0; tx < g.tilesX; ++tx) {
            const double v = shownHeat_[g.tileIndex(tx, ty)];
            if (std::isnan(v)) continue; // no geometry (or no per-tile figure): nothing drawn
            const vtkIdType q[4] = {pid(tx, ty), pid(tx + 1, ty), pid(tx + 1, ty + 1), pid(tx, ty + 1)};
            quads->InsertNextCell(4, q);
            values->InsertNextValue(v);
            maxHeat = std::max(maxHeat, v);
        }
    heatData_->SetPoints(pts);
    heatData_->SetPolys(quads);
    heatData_->GetCellData()->SetScalars(values);
    if (mode == lc::HeatMode::Overflow) {
        // One hue, the orange that marks over-full lists everywhere (the
        // heat map PNGs' frames): only over-full tiles are drawn at all.
        lut_->SetHueRange(0.08, 0.08);
        lut_->SetSaturationRange(0.6, 1.0);
        lut_->SetValueRange(1.0, 1.0);
        lut_->SetTableRange(0, std::max(1.0, maxHeat));
        legendTitle_ = "dropped\nentries";
        legend_->SetLabelFormat("%.0f");
        legend_->SetNumberOfLabels(maxHeat < 5 ? int(std::max(1.0, maxHeat)) + 1 : 5);
    } else if (mode == lc::HeatMode::Efficiency) {
        lut_->SetSaturationRange(0.9, 0.9);
        lut_->SetValueRange(1.0, 1.0);
        lut_->SetHueRange(0.0, 0.667);
        lut_->SetTableRange(0, 1);
        legendTitle_ = "efficiency\nper tile";
        legend_->SetLabelFormat("%.2f");
        legend_->SetNumberOfLabels(5);
    } else {
        lut_->SetSaturationRange(0.9, 0.9);
        lut_->SetValueRange(1.0, 1.0);
        lut_->SetHueRange(0.667, 0.0);
        const double top = std::max(1.0, maxHeat);
        lut_->SetTableRange(0, top);
        legendTitle_ = mode == lc::HeatMode::ListLength       ? "lights\nper tile"
                       : mode == lc::HeatMode::FalsePositives ? "false\npositives"
                                                              : "false\nnegatives";
        legend_->SetLabelFormat("%.0f");
        // Counts: below 5 a label per whole number (five evenly spaced labels
        // over 0..2 would read 0, 0, 1, 2, 2).
        legend_->SetNumberOfLabels(top < 5 ? int(top) + 1 : 5);
    }
    legend_->SetTitle(barTitle(legendTitle_, legendPlace_ == LegendPlace::Below).c_str());
    lut_->Build();

    vtkNew<vtkCellArray> lines;
    for (std::uint32_t i = 0; i <= g.tilesX; ++i) {
        const vtkIdType l[2] = {pid(i, 0), pid(i, g.tilesY)};
        lines->InsertNextCell(2, l);
    }
    for (std::uint32_t j = 0; j <= g.tilesY; ++j) {
        const vtkIdType l[2] = {pid(0, j), pid(g.tilesX, j)};
        lines->InsertNextCell(2, l);
    }
    gridData_->SetPoints(pts);
    gridData_->SetLines(lines);
    updateGridVisibility();

    const std::string what = run->custom ? "custom " + std::filesystem::path(run->custom->source).filename().string() +
                                               " (" + run->custom->lists + ")"
                                         : std::string(lc::toString(run->result.algorithm));
    heatCaption_ = what + "  " + std::to_string(g.tilesX) + "x" +
                   std::to_string(g.tilesY) + " tiles of " + std::to_string(g.tileSize) + " px";
    // The engine limits, when they took something: over-full lists and lights past the limit.
    if (const lc::ListLimits& lim = run->result.limits; !run->custom && !lim.empty())
        heatCaption_ += "  |  " + std::to_string(lim.overflowLists.size()) + " over-full" +
                        (lim.lightsOverLimit ? ", " + std::to_string(lim.lightsOverLimit) + " past limit" : std::string());
    updateImage();
    updateLegendAndCaption();
    updateSelectedTile();
    updateReverseLookup();
    scheduleRender();
}

void CameraView::updateLegendAndCaption() {
    const auto run = doc_->runs().runOutput();
    legend_->SetVisibility(run && imageMode_ == ImageMode::Heat);
    diffLegend_->SetVisibility(false);
    {
        // The caption says the zoom, and how to get back.
        std::string text = heatCaption_;
        if (zoom_ > 1.0 + 1e-9) {
            char z[96];
            std::snprintf(z, sizeof z, "  zoom %.3gx", zoom_);
            text += z;
        }
        caption_->SetInput(text.c_str());
        caption_->SetDisplayPosition(6, legendPlace_ == LegendPlace::Below ? 4 : 6);
    }
    imageLabel_->SetVisibility(run && imageMode_ != ImageMode::Heat);
    if (!imageLabel_->GetVisibility()) return;
    QString text = imageMode_ == ImageMode::ShadedCulled ? tr("shaded, culled lists")
                   : imageMode_ == ImageMode::ShadedAll  ? tr("shaded, all lights")
                                                         : tr("abs(culled - all lights)");
    if (imageActor_->GetVisibility()) {
        const auto& m = picturesRun_->truth.metrics;
        if (imageMode_ == ImageMode::Difference) {
            text += tr(", white = %1").arg(m.imageMaxError, 0, 'g', 4);
            diffLut_->SetTableRange(0, m.imageMaxError > 0 ? m.imageMaxError : 1.0);
            diffLegend_->SetVisibility(true);
        } else {
            text += tr(", exposure %1").arg(picturesExposure_, 0, 'g', 4);
        }
        text += tr("\nimage RMSE %1, max %2 (%3)")
                    .arg(m.imageRmse, 0, 'g', 6)
                    .arg(m.imageMaxError, 0, 'g', 6)
                    .arg(QString::fromStdString(picturesRun_->result.backend));
        if (picturesRun_ != run) text += tr(", shading the newer run...");
    } else {
        text += tr(": shading...");
    }
    imageLabel_->SetInput(text.toUtf8().constData());
}

void CameraView::updateReverseLookup() {
    clearOverlay(reverseData_);
    reverseTiles_.clear();
    const auto run = doc_->runs().runOutput();
    const int light = doc_->selection().currentLight();
    if (!run || doc_->runs().runIsStale() || !doc_->viewOptions().overlays().reverseLookup || light < 0 ||
        std::size_t(light) >= run->lights.size())
        return;
    const lc::TileGrid& g = run->result.grid;
    for (std::uint32_t t : lc::tilesHoldingLight(run->result, std::uint32_t(light))) reverseTiles_.push_back(int(t));
    // One closed outline per tile, inset by a tenth of a tile so that
    // neighbouring outlines stay apart.
    vtkNew<vtkPoints> pts;
    vtkNew<vtkCellArray> loops;
    const double inset = 0.1 * g.tileSize;
    for (int t : reverseTiles_) {
        const auto rect = g.tileRect(std::uint32_t(t) % g.tilesX, std::uint32_t(t) / g.tilesX);
        const double x0 = rect.x0 + inset, x1 = rect.x1 - inset, y0 = rect.y0 + inset, y1 = rect.y1 - inset;
        const vtkIdType a = pts->InsertNextPoint(x0 / g.width, 1 - y0 / g.height, 0);
        pts->InsertNextPoint(x1 / g.width, 1 - y0 / g.height, 0);
        pts->InsertNextPoint(x1 / g.width, 1 - y1 / g.height, 0);
        pts->InsertNextPoint(x0 / g.width, 1 - y1 / g.height, 0);
        const vtkIdType ids[5] = {a, a + 1, a + 2, a + 3, a};
        loops->InsertNextCell(5, ids);
    }
    reverseData_->SetPoints(pts);
    reverseData_->SetLines(loops);
}

void CameraView::updateSelectedTile() {
    clearOverlay(selData_);
    const auto run = doc_->runs().runOutput();
    const int tile = doc_->selection().selectedTile();
    if (!run || tile < 0 || std::uint32_t(tile) >= run->result.grid.tileCount()) return;
    const lc::TileGrid& g = run->result.grid;
    const auto rect = g.tileRect(std::uint32_t(tile) % g.tilesX, std::uint32_t(tile) / g.tilesX);
    vtkNew<vtkPoints> pts;
    pts->InsertNextPoint(rect.x0 / double(g.width), 1 - rect.y0 / double(g.height), 0);
    pts->InsertNextPoint(rect.x1 / double(g.width), 1 - rect.y0 / double(g.height), 0);
    pts->InsertNextPoint(rect.x1 / double(g.width), 1 - rect.y1 / double(g.height), 0);
    pts->InsertNextPoint(rect.x0 / double(g.width), 1 - rect.y1 / double(g.height), 0);
    vtkNew<vtkCellArray> loop;
    const vtkIdType ids[5] = {0, 1, 2, 3, 0};
    loop->InsertNextCell(5, ids);
    selData_->SetPoints(pts);
    selData_->SetLines(loop);
}

} // namespace lcui
