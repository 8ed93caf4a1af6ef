#include "document/explained_selection.hpp"

#include "document/document.hpp"

#include "culling/math/projection.hpp"

namespace lcui {

const ExplainedSelection::Result& ExplainedSelection::of(const Document& doc) {
    const std::pair<unsigned long long, unsigned long long> now{doc.selection().revision(), doc.runs().revision()};
    if (valid_ && revisions_ == now) return result_;
    revisions_ = now;
    result_ = {};
    try {
        result_.explanation = compute(doc);
    } catch (const std::exception& e) {
        result_.error = e.what();
    }
    valid_ = true;
    return result_;
}

std::optional<lc::Explanation> ExplainedSelection::compute(const Document& doc) {
    const auto run = doc.runs().runOutput();
    const Selection& sel = doc.selection();
    const int tile = sel.selectedTile();
    const int light = sel.currentLight();
    if (!run || !run->truthComputed || doc.runs().runIsStale() || tile < 0 || light < 0 ||
        std::size_t(light) >= run->lights.size())
        return std::nullopt;
    const lc::CullResult& r = run->result;
    const lc::Projection proj(doc.scene().camera);
    const int sub = r.listsPerTile <= 1 ? -1 : sel.selectedCell();
    std::uint32_t list = 0;
    if (sub >= 0 || r.listsPerTile <= 1) {
        list = r.listOf(std::uint32_t(tile), sub);
    } else {
        // A tile of several lists without a cell: the list picked in the
        // tile inspector, else the first that holds or needs the light, else
        // the first.
        const std::uint32_t first = std::uint32_t(tile) * r.listsPerTile;
        const int picked = sel.explainedList();
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

} // namespace lcui
