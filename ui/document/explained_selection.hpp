#pragma once
// The explanation of the document's selection (lc::explainLight): the
// selected tile (its selected cell, the list picked in the tile inspector, or
// the first list that holds or needs the light) and the current light, in
// the shown run once its ground truth is in. Worked out once per selection
// and run (their revisions: no one has to remember to invalidate it), when
// first asked for, and shared by all who show it (the Explain panel, the
// inspector's Explain markers).

#include "culling/diagnostics/explain.hpp"

#include <optional>
#include <string>
#include <utility>

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

private:
    static std::optional<lc::Explanation> compute(const Document& doc);
    bool valid_ = false;
    std::pair<unsigned long long, unsigned long long> revisions_; // selection's, run state's
    Result result_;
};

} // namespace lcui
