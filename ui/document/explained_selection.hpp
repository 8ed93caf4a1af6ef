#pragma once
// The explanation of the document's selection (lc::explainLight): the
// selected tile (its selected cell, the list picked in the tile inspector, or
// the first list that holds or needs the light) and the current light, in
// the shown run once its ground truth is in. Worked out once per selection
// and run, when first asked for, and shared by all who show it (the Explain
// panel, the inspector's Explain markers).

#include "culling/diagnostics/explain.hpp"

#include <optional>
#include <string>

namespace lcui {

class Document;

class ExplainedSelection {
public:
    struct Result {
        std::optional<lc::Explanation> explanation; // nullopt: nothing to explain, or `error`
        std::string error;                          // what lc::explainLight threw
    };
    // The explanation of `doc`'s selection as it is now.
    const Result& of(const Document& doc);
    // The selection or the run changed (the Document calls it before anyone
    // else hears of the change).
    void invalidate() { valid_ = false; }

private:
    static std::optional<lc::Explanation> compute(const Document& doc);
    bool valid_ = false;
    Result result_;
};

} // namespace lcui
