#pragma once
// The editor features over one checked document: hover, go-to-definition, completion and
// the outline. Each answers with the protocol's JSON (null when there is nothing to say).
#include <nlohmann/json.hpp>

#include "fleet/fleet.h"
#include "lsp/document.h"
#include "lsp/text.h"

namespace eamos::lsp {

/// A drone's capability (after `Drone.`) with its signatures and units; a drone, a drone
/// type, a block or a control structure with what it is.
nlohmann::json hover(const Document& doc, const fleet::Fleet& fleet, Position at, Encoding enc);
/// Where a block (func) or a drone (var) under the cursor is declared.
nlohmann::json definition(const Document& doc, Position at, Encoding enc);
/// After `Drone.`: the capabilities of that drone's type; elsewhere: drones, blocks,
/// control structures and keywords.
nlohmann::json completion(const Document& doc, const fleet::Fleet& fleet, Position at, Encoding enc);
/// The drones and blocks, as DocumentSymbol[] (`hierarchical`) or SymbolInformation[].
nlohmann::json document_symbols(const Document& doc, Encoding enc, bool hierarchical);

}  // namespace eamos::lsp
