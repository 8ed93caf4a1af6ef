#include "views/overlay_actors_parts.hpp"

#include "document/document.hpp"

namespace lcui {

using namespace overlay_parts;

namespace {

// The run still describes the scene and its grid is the camera's.
bool usableRun(const Document& doc) {
    const auto run = doc.runs().runOutput();
    const lc::Camera& cam = doc.scene().camera;
    return run && !doc.runs().runIsStale() && run->result.grid.width == cam.width && run->result.grid.height == cam.height &&
           run->result.grid.tileSize == cam.tileSize && cam.validate().empty();
}

} // namespace

std::optional<std::vector<int>> InspectorOverlays::tileListLights(const Document& doc) {
    const int tile = doc.selection().selectedTile();
    if (!usableRun(doc) || tile < 0) return std::nullopt;
    const auto run = doc.runs().runOutput();
    const lc::CullResult& r = run->result;
    if (std::uint32_t(tile) >= r.grid.tileCount()) return std::nullopt;
    auto [first, count] = r.tileLists(std::uint32_t(tile));
    // As the tile inspector's rows (lc::tileLightRows): a cell of halfz or
    // clustered has a list of its own.
    const int cell = doc.selection().selectedCell();
    if (cell >= 0 && (r.algorithm == lc::Algorithm::HalfZ || r.layout() == lc::Algorithm::Clustered) &&
        std::uint32_t(cell) < count) {
        first += std::uint32_t(cell);
        count = 1;
    }
    const std::size_t n = doc.scene().lights.size();
    std::vector<char> in(n, 0);
    for (std::uint32_t l = first; l < first + count && l < r.listCountTotal(); ++l)
        for (std::uint32_t k = 0; k < r.listCount[l]; ++k) {
            const std::uint32_t light = r.lightIndices[r.listOffset[l] + k];
            if (light < n) in[light] = 1;
        }
    std::vector<int> out;
    for (std::size_t i = 0; i < n; ++i)
        if (in[i]) out.push_back(int(i));
    return out;
}

InspectorOverlays::InspectorOverlays(vtkRenderer* renderer, vtkSphereSource* sphere) : d_(new Impl) {
    d_->renderer = renderer;
    d_->tileSolidA = makeActor(d_->tileSolid, 0.35, 0.8, 1.0, 0.12);
    d_->tileOutlineA = makeActor(d_->tileOutline, 0.35, 0.85, 1.0, 1.0, 2.5);
    d_->cellFillA = makeActor(d_->cellFill, 1.0, 0.55, 0.15, 0.3);
    d_->cellOutlineA = makeActor(d_->cellOutline, 0.85, 0.85, 0.85, 0.45);
    d_->cellSelectedA = makeActor(d_->cellSelected, 1.0, 0.95, 0.2, 0.45, 3.0);
    d_->splitA = makeActor(d_->splitQuad, 1.0, 0.3, 0.9, 0.4);
    d_->rangeA = makeActor(d_->lightRange, 0.3, 1.0, 0.35, 1.0, 3.0);
    d_->zbinSlabA = makeActor(d_->zbinSlab, 0.3, 1.0, 0.35, 0.15, 2.0); // the light range's green, translucent
    d_->reverseA = makeActor(d_->reverse, 1.0, 0.3, 1.0, 0.8, 1.5);
    d_->spotSphereA = makeActor(d_->spotSphere, 1.0, 0.5, 0.7, 1.0, 2.0); // pink: a spot is often white
    d_->spotPassedA = makeActor(d_->spotPassed, 0.25, 0.55, 1.0, 1.0, 2.0); // not the cell range's green
    d_->spotRejectedA = makeActor(d_->spotRejected, 1.0, 0.25, 0.2, 1.0, 2.0);
    // Colours no other overlay uses: violet (red when it rejected), white.
    d_->explainPlaneA = makeActor(d_->explainPlane, 0.55, 0.35, 1.0, 0.45);
    // Its outline opaque and thick: visible through the translucent cells.
    d_->explainEdgeA = makeActor(d_->explainPlane, 0.55, 0.35, 1.0, 1.0, 4.0);
    d_->explainEdgeA->GetProperty()->SetRepresentationToWireframe();
    d_->explainPixelA = makeActor(d_->explainPixel, 1.0, 1.0, 1.0, 1.0, 2.5);
    d_->explainPixelA->GetProperty()->SetPointSize(12);
    d_->explainPixelA->GetProperty()->SetRenderPointsAsSpheres(true);
    for (vtkActor* a : {d_->spotSphereA.Get(), d_->spotPassedA.Get(), d_->spotRejectedA.Get(),
                        d_->explainPlaneA.Get(), d_->explainEdgeA.Get(), d_->explainPixelA.Get()}) {
        a->SetVisibility(false);
        renderer->AddActor(a);
    }
    d_->spotCaption->GetTextProperty()->SetFontSize(13);
    d_->spotCaption->GetTextProperty()->SetColor(1.0, 1.0, 0.85);
    d_->spotCaption->GetTextProperty()->SetBackgroundColor(0, 0, 0);
    d_->spotCaption->GetTextProperty()->SetBackgroundOpacity(0.55);
    d_->spotCaption->SetDisplayPosition(8, 8);
    d_->spotCaption->SetVisibility(false);
    renderer->AddActor2D(d_->spotCaption);

    // All tiles: one wireframe actor, lines coloured by the tile's list length.
    d_->lut->SetHueRange(0.667, 0.0);
    d_->lut->SetNumberOfTableValues(256);
    d_->lut->Build();
    vtkNew<vtkPolyDataMapper> allMapper;
    allMapper->SetInputData(d_->allTiles);
    allMapper->SetScalarModeToUseCellData();
    allMapper->SetLookupTable(d_->lut);
    allMapper->UseLookupTableScalarRangeOn();
    d_->allTilesA = vtkSmartPointer<vtkActor>::New();
    d_->allTilesA->SetMapper(allMapper);
    d_->allTilesA->GetProperty()->SetLighting(false);
    // Opaque: 12 lines x ~8,000 tiles stay out of the depth-peeling passes.
    d_->allTilesA->GetProperty()->SetOpacity(1.0);
    d_->allTilesA->PickableOff();

    // Listed lights: their spheres, brighter than the dimmed glyph actor;
    // missing lights: red.
    auto glyphActor = [&](vtkGlyph3D* g, vtkSmartPointer<vtkPolyData>& data, vtkActor* a, bool colored) {
        data = lightsToPolyData({});
        g->SetSourceConnection(sphere->GetOutputPort());
        g->SetInputData(data);
        g->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "radius");
        g->SetInputArrayToProcess(3, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "color");
        g->SetScaleModeToScaleByScalar();
        g->ClampingOff();
        g->OrientOff();
        g->SetColorModeToColorByScalar();
        vtkNew<vtkPolyDataMapper> m;
        m->SetInputConnection(g->GetOutputPort());
        if (colored) {
            m->SetScalarModeToUsePointFieldData();
            m->SelectColorArray("color");
            m->SetColorModeToDirectScalars();
            m->ScalarVisibilityOn();
        } else {
            m->ScalarVisibilityOff();
        }
        a->SetMapper(m);
        a->GetProperty()->BackfaceCullingOn();
        a->PickableOff();
    };
    glyphActor(d_->listedGlyph, d_->listedData, d_->listedA, true);
    d_->listedA->GetProperty()->SetOpacity(0.45);
    d_->listedGlyphMapper = d_->listedA->GetMapper();
    d_->listedRings->SetInputData(d_->listedData);
    d_->listedRings->SetCamera(renderer->GetActiveCamera());
    d_->listedRingMapper->SetInputConnection(d_->listedRings->GetOutputPort());
    d_->listedRingMapper->SetScalarModeToUsePointFieldData();
    d_->listedRingMapper->SelectColorArray("color");
    d_->listedRingMapper->SetColorModeToDirectScalars();
    d_->listedRingMapper->ScalarVisibilityOn();
    glyphActor(d_->missingGlyph, d_->missingData, d_->missingA, false);
    d_->missingA->GetProperty()->SetColor(1.0, 0.1, 0.1);
    d_->missingA->GetProperty()->SetOpacity(0.7);

    for (vtkActor* a : {d_->allTilesA.Get(), d_->tileSolidA.Get(), d_->tileOutlineA.Get(), d_->cellFillA.Get(),
                        d_->cellOutlineA.Get(), d_->cellSelectedA.Get(), d_->splitA.Get(), d_->rangeA.Get(),
                        d_->reverseA.Get(), static_cast<vtkActor*>(d_->listedA.Get()),
                        static_cast<vtkActor*>(d_->missingA.Get()), d_->zbinSlabA.Get()}) {
        a->SetVisibility(false);
        renderer->AddActor(a);
    }
}

InspectorOverlays::~InspectorOverlays() = default;

vtkPolyData* InspectorOverlays::tileSolid() const { return d_->tileSolid; }
vtkPolyData* InspectorOverlays::cellFill() const { return d_->cellFill; }
vtkPolyData* InspectorOverlays::cellOutline() const { return d_->cellOutline; }
vtkPolyData* InspectorOverlays::splitQuad() const { return d_->splitQuad; }
vtkPolyData* InspectorOverlays::lightRange() const { return d_->lightRange; }
vtkPolyData* InspectorOverlays::allTiles() const { return d_->allTiles; }
vtkPolyData* InspectorOverlays::reverse() const { return d_->reverse; }
vtkActor* InspectorOverlays::allTilesActor() const { return d_->allTilesA; }
vtkActor* InspectorOverlays::listedActor() const { return d_->listedA; }
vtkPolyData* InspectorOverlays::spotCullSphere() const { return d_->spotSphere; }
vtkPolyData* InspectorOverlays::spotChunksPassed() const { return d_->spotPassed; }
vtkPolyData* InspectorOverlays::spotChunksRejected() const { return d_->spotRejected; }
vtkTextActor* InspectorOverlays::spotCaption() const { return d_->spotCaption; }
vtkPolyData* InspectorOverlays::explainPlane() const { return d_->explainPlane; }
vtkPolyData* InspectorOverlays::zbinSlab() const { return d_->zbinSlab; }
vtkPolyData* InspectorOverlays::explainPixel() const { return d_->explainPixel; }

void InspectorOverlays::update(const Document& doc) {
    for (vtkPolyData* pd : {d_->tileSolid.Get(), d_->tileOutline.Get(), d_->cellFill.Get(), d_->cellOutline.Get(),
                            d_->cellSelected.Get(), d_->splitQuad.Get(), d_->lightRange.Get(), d_->reverse.Get(),
                            d_->zbinSlab.Get()})
        pd->Initialize();
    listed_.clear();
    missing_.clear();
    reverseLists_.clear();
    dim_ = false;
    listedRings_ = false;
    listedLeftOut_ = 0;

    const auto run = doc.runs().runOutput();
    const lc::Camera& cam = doc.scene().camera;
    const auto& opt = doc.viewOptions().overlays();
    const bool usable = run && !doc.runs().runIsStale() && run->result.grid.width == cam.width && run->result.grid.height == cam.height &&
                        run->result.grid.tileSize == cam.tileSize && cam.validate().empty();
    auto show = [](vtkActor* a, bool on) { a->SetVisibility(on); };
    if (!usable) {
        for (vtkActor* a : {d_->allTilesA.Get(), d_->tileSolidA.Get(), d_->tileOutlineA.Get(), d_->cellFillA.Get(),
                            d_->cellOutlineA.Get(), d_->cellSelectedA.Get(), d_->splitA.Get(), d_->rangeA.Get(),
                            d_->reverseA.Get(), static_cast<vtkActor*>(d_->listedA.Get()),
                            static_cast<vtkActor*>(d_->missingA.Get()), d_->zbinSlabA.Get()})
            show(a, false);
        d_->allTiles->Initialize();
        allTilesRun_ = nullptr;
        updateSpotPrimitive(doc, nullptr, -1);
        updateExplainMarkers(doc);
        return;
    }
    const lc::CullResult& r = run->result;
    const lc::Projection proj(cam);
    const glm::dmat4 w = lc::worldFromView(cam);
    const int tile = doc.selection().selectedTile();
    const bool tileOk = tile >= 0 && std::uint32_t(tile) < r.grid.tileCount();

    // Selected tile frustum.
    if (tileOk && opt.tileFrustum)
        if (const auto chunk = lc::tileFrustum(r, proj, run->lights, std::uint32_t(tile))) {
            ChunkGeometry solid, outline;
            solid.worldFromView = outline.worldFromView = w;
            solid.faces(*chunk);
            outline.edges(*chunk);
            solid.into(d_->tileSolid);
            outline.into(d_->tileOutline);
        }
    show(d_->tileSolidA, d_->tileSolid->GetNumberOfCells() > 0);
    show(d_->tileOutlineA, d_->tileOutline->GetNumberOfCells() > 0);

    // Depth cells, the halfz split, the selected cell, the light's cell range.
    const std::vector<lc::DepthCell> cells =
        tileOk ? lc::tileCells(r, proj, std::uint32_t(tile)) : std::vector<lc::DepthCell>{};
    if (opt.cells && !cells.empty()) {
        ChunkGeometry fill, outline, selected, split;
        fill.worldFromView = outline.worldFromView = selected.worldFromView = split.worldFromView = w;
        for (const lc::DepthCell& c : cells) {
            if (c.occupied) fill.faces(c.chunk);
            outline.edges(c.chunk);
            if (int(c.cell) == doc.selection().selectedCell()) {
                selected.faces(c.chunk);
                selected.edges(c.chunk);
            }
        }
        if (r.algorithm == lc::Algorithm::HalfZ && cells.size() == 2) split.nearFace(cells[1].chunk);
        fill.into(d_->cellFill);
        outline.into(d_->cellOutline);
        selected.into(d_->cellSelected);
        split.into(d_->splitQuad);
    }
    show(d_->cellFillA, d_->cellFill->GetNumberOfCells() > 0);
    show(d_->cellOutlineA, d_->cellOutline->GetNumberOfCells() > 0);
    show(d_->cellSelectedA, d_->cellSelected->GetNumberOfCells() > 0);
    show(d_->splitA, d_->splitQuad->GetNumberOfCells() > 0);

    const int light = doc.selection().currentLight();
    const bool lightOk = light >= 0 && std::size_t(light) < run->lights.size();
    if (opt.lightCellRange && lightOk && !cells.empty()) {
        const std::uint32_t range =
            lc::lightCellRange(r, std::uint32_t(tile), run->lights.centers[std::size_t(light)],
                               run->lights.radii[std::size_t(light)]);
        ChunkGeometry g;
        g.worldFromView = w;
        for (const lc::DepthCell& c : cells)
            if ((range >> c.cell) & 1u) g.edges(c.chunk);
        g.into(d_->lightRange);
    }
    show(d_->rangeA, d_->lightRange->GetNumberOfCells() > 0);

    // zbin: the slab of the camera frustum over the current light's bins.
    if (opt.lightCellRange && lightOk)
        if (const auto slab = lc::zbinLightSlab(r, proj, run->lights, std::uint32_t(light))) {
            ChunkGeometry g;
            g.worldFromView = w;
            g.faces(*slab);
            g.edges(*slab);
            g.into(d_->zbinSlab);
        }
    show(d_->zbinSlabA, d_->zbinSlab->GetNumberOfCells() > 0);

    // Reverse look-up: the volumes whose lists hold the current light.
    if (opt.reverseLookup && lightOk) {
        reverseLists_ = lc::listsHoldingLight(r, std::uint32_t(light));
        ChunkGeometry g;
        g.worldFromView = w;
        const bool perCell = r.algorithm == lc::Algorithm::HalfZ || r.layout() == lc::Algorithm::Clustered;
        if (r.algorithm != lc::Algorithm::All) {
            std::uint32_t lastTile = ~0u;
            std::vector<lc::DepthCell> tileCellsCache;
            for (std::uint32_t l : reverseLists_) {
                const std::uint32_t t = r.tileOfList(l);
                if (perCell) {
                    if (t != lastTile) tileCellsCache = lc::tileCells(r, proj, t);
                    for (const auto& c : tileCellsCache)
                        if (c.list == l) g.edges(c.chunk);
                } else if (const auto chunk = lc::tileFrustum(r, proj, run->lights, t)) {
                    g.edges(*chunk);
                }
                lastTile = t;
            }
        }
        g.into(d_->reverse);
    }
    show(d_->reverseA, d_->reverse->GetNumberOfCells() > 0);

    // Listed lights of the selected tile (or cell) highlighted, missing in red.
    const auto& lights = doc.scene().lights;
    bool drawListed = false;
    if (opt.listHighlight && tileOk) {
        const auto rows = lc::tileLightRows(*run, proj, std::uint32_t(tile), doc.selection().selectedCell());
        std::vector<lc::PointLight> missingL;
        for (const auto& row : rows) {
            if (row.light >= lights.size()) continue;
            auto& ids = row.verdict == lc::Verdict::Missing ? missing_ : listed_;
            if (std::find(ids.begin(), ids.end(), int(row.light)) != ids.end()) continue;
            ids.push_back(int(row.light));
            if (row.verdict == lc::Verdict::Missing) missingL.push_back(lights[row.light]);
        }
        // View > Lights: with only the tile's lights shown the view draws the
        // listed ones itself (undimmed); hidden lights hide these too.
        drawListed = opt.showLights && !opt.onlyTileLights;
        using LD = OverlayOptions::LightDisplay;
        const std::size_t cap = std::size_t(std::max(opt.sphereCap, 1));
        listedRings_ = opt.lights == LD::Outlines || (opt.lights == LD::Auto && listed_.size() > cap);
        std::vector<int> shown = listed_;
        if (!listedRings_ && shown.size() > cap) {
            // The spheres nearest the tile's frustum first.
            glm::dvec3 centre(0.0);
            if (const auto chunk = lc::tileFrustum(r, proj, run->lights, std::uint32_t(tile))) {
                for (const glm::dvec3& v : chunk->corners) centre += v;
                centre = glm::dvec3(w * glm::dvec4(centre / 8.0, 1.0));
            }
            std::stable_sort(shown.begin(), shown.end(), [&](int a, int b) {
                return glm::length(lights[std::size_t(a)].position - centre) <
                       glm::length(lights[std::size_t(b)].position - centre);
            });
            listedLeftOut_ = drawListed ? shown.size() - cap : 0;
            shown.resize(cap);
        }
        std::vector<lc::PointLight> listedL;
        for (int i : shown) listedL.push_back(lights[std::size_t(i)]);
        d_->listedData = lightsToPolyData(listedL);
        d_->missingData = lightsToPolyData(missingL);
        d_->listedGlyph->SetInputData(d_->listedData);
        d_->listedRings->SetInputData(d_->listedData);
        d_->missingGlyph->SetInputData(d_->missingData);
        // Rings are lines: bright and opaque enough to stand out over the
        // dimmed rings of the other lights; spheres stay translucent.
        d_->listedA->SetMapper(listedRings_ ? static_cast<vtkMapper*>(d_->listedRingMapper.Get())
                                            : d_->listedGlyphMapper.Get());
        d_->listedA->GetProperty()->SetOpacity(listedRings_ ? 0.9 : 0.45);
        d_->listedA->GetProperty()->SetLighting(!listedRings_);
        d_->listedA->GetProperty()->SetLineWidth(listedRings_ ? 2.0 : 1.0);
        d_->listedRings->SetCamera(d_->renderer->GetActiveCamera());
        dim_ = drawListed;
    }
    show(d_->listedA, drawListed && !listed_.empty());
    show(d_->missingA, !missing_.empty());

    // Every tile's frustum: rebuilt only for a new run (or when turned on).
    if (opt.allTileFrustums) {
        if (allTilesRun_ != run.get()) {
            ChunkGeometry g;
            g.worldFromView = w;
            vtkNew<vtkDoubleArray> len;
            len->SetName("list_length");
            const auto heat = lc::tileHeat(*run, lc::HeatMode::ListLength);
            double maxLen = 1;
            for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
                const auto chunk = lc::tileFrustum(r, proj, run->lights, t);
                if (!chunk) continue;
                g.edges(*chunk);
                const double v = std::isnan(heat[t]) ? 0.0 : heat[t];
                for (int e = 0; e < 12; ++e) len->InsertNextValue(v);
                maxLen = std::max(maxLen, v);
            }
            g.into(d_->allTiles);
            d_->allTiles->GetCellData()->SetScalars(len);
            d_->lut->SetTableRange(0, maxLen);
            allTilesRun_ = run.get();
        }
    } else {
        d_->allTiles->Initialize();
        allTilesRun_ = nullptr;
    }
    show(d_->allTilesA, d_->allTiles->GetNumberOfCells() > 0);

    updateSpotPrimitive(doc, run.get(), tileOk ? tile : -1);
    updateExplainMarkers(doc);
}

} // namespace lcui
