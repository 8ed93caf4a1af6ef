#include "panels/explain_panel.hpp"

#include "document/document.hpp"

#include "culling/core/errors.hpp"
#include "culling/math/projection.hpp"

#include <QFontDatabase>
#include <QLabel>
#include <QPlainTextEdit>
#include <QTextOption>
#include <QVBoxLayout>

namespace lcui {

ExplainPanel::ExplainPanel(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(4, 4, 4, 4);
    verdict_ = new QLabel;
    verdict_->setObjectName("explainVerdict");
    verdict_->setWordWrap(true);
    text_ = new QPlainTextEdit;
    text_->setObjectName("explainText");
    text_->setReadOnly(true);
    // Wrapped at the dock's width: each test's numbers (signed distance
    // against -r) sit at the end of its line, past a 330 px dock's edge.
    text_->setLineWrapMode(QPlainTextEdit::WidgetWidth);
    text_->setWordWrapMode(QTextOption::WrapAtWordBoundaryOrAnywhere);
    text_->setFont(QFontDatabase::systemFont(QFontDatabase::FixedFont));
    layout->addWidget(verdict_);
    layout->addWidget(text_, 1);
    connect(doc_, &Document::selectionChanged, this, &ExplainPanel::refresh);
    connect(doc_, &Document::tileSelectionChanged, this, &ExplainPanel::refresh);
    connect(doc_, &Document::runOutputChanged, this, &ExplainPanel::refresh);
    connect(doc_, &Document::runWentStale, this, &ExplainPanel::refresh);
    refresh();
}

std::optional<lc::Explanation> explainSelection(const Document& doc) {
    const auto run = doc.runOutput();
    const int tile = doc.selectedTile();
    const int light = doc.currentLight();
    if (!run || !run->truthComputed || doc.runIsStale() || tile < 0 || light < 0 ||
        std::size_t(light) >= run->lights.size())
        return std::nullopt;
    const lc::CullResult& r = run->result;
    const lc::Projection proj(doc.scene().camera);
    int sub = doc.selectedCell();
    if (r.listsPerTile <= 1) sub = -1;
    std::uint32_t list = 0;
    if (sub >= 0 || r.listsPerTile <= 1) {
        list = r.listOf(std::uint32_t(tile), sub);
    } else {
        // A tile of several lists without a cell: the list picked in the
        // tile inspector, else the first that holds or needs the light, else
        // the first.
        const std::uint32_t first = std::uint32_t(tile) * r.listsPerTile;
        const int picked = doc.explainedList();
        list = first;
        if (picked >= 0 && std::uint32_t(picked) >= first && std::uint32_t(picked) < first + r.listsPerTile) {
            list = std::uint32_t(picked);
        } else {
            for (const lc::TileLightRow& row : lc::tileLightRows(*run, proj, std::uint32_t(tile), -1))
                if (row.light == std::uint32_t(light)) {
                    list = row.list;
                    break;
                }
        }
    }
    return lc::explainLight(*run, proj, list, std::uint32_t(light));
}

void ExplainPanel::refresh() {
    explanation_.reset();
    std::optional<lc::Explanation> e;
    QString error;
    try {
        e = explainSelection(*doc_);
    } catch (const std::exception& ex) {
        error = QString::fromStdString(ex.what());
    }
    if (!e) {
        const auto run = doc_->runOutput();
        const bool selected = doc_->selectedTile() >= 0 && doc_->currentLight() >= 0;
        verdict_->setText(!error.isEmpty()       ? error
                          : doc_->runIsStale() ? tr("The scene changed since the last run: run culling again (F5) "
                                                    "to explain it.")
                          // A Live edit's lists come before their ground truth.
                          : selected && run && !run->truthComputed
                              ? tr("Waiting for the ground truth of run %1 (a Live edit shows its lists first)...")
                                    .arg(doc_->runGeneration())
                              : tr("Select a tile (click the camera view) and a light (the scene tree or "
                                   "a double-click on a row of the tile inspector) to see why the light is, or is not, in "
                                   "that tile's list."));
        verdict_->setStyleSheet({});
        text_->clear();
        return;
    }
    explanation_ = std::move(e);
    const std::size_t light = explanation_->light;
    const std::string name = light < doc_->scene().lights.size() ? doc_->scene().lights[light].name : "";
    text_->setPlainText(QString::fromStdString(explanation_->text(name)));
    verdict_->setText(QString::fromStdString(explanation_->verdict));
    const bool missing = !explanation_->listed && explanation_->pixelsNeeding > 0;
    verdict_->setStyleSheet(missing ? "QLabel { color: white; background: rgb(200,40,40); padding: 2px; }" : "");
}

} // namespace lcui
