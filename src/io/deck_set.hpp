// The command line's --set KEY=VALUE overrides, applied to the deck's TOML tree before it is
// read (deck.hpp, load_deck, describes KEY and VALUE). Internal to the deck reader.
#pragma once

#include <toml++/toml.h>

#include <string>

#include "io/deck_diagnostics.hpp"

namespace dem2d::deck {

// Applies one override ("drum.speed=1.5") to `root`, and records every node it makes in
// `origins` with the option's text ("--set drum.speed=1.5"), so that a message about such a
// value names the option. Setting one key of an alternative group (deck_schema.hpp) removes
// the deck's value of the others in the same table. A problem with the option itself (not with
// the value it sets, which the validation reports) is an error naming the option.
void apply_override(toml::table& root, const std::string& option, Origins& origins,
                    Diagnostics& diag);

}  // namespace dem2d::deck
