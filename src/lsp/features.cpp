#include "lsp/features.h"

#include <algorithm>
#include <climits>

#include "lang/checker.h"

namespace eamos::lsp {

using lang::TokenKind;
using nlohmann::json;

namespace {

// LSP's CompletionItemKind and SymbolKind values used here.
constexpr int kItemMethod = 2, kItemFunction = 3, kItemVariable = 6, kItemProperty = 10, kItemKeyword = 14;
constexpr int kSymbolFunction = 12, kSymbolVariable = 13;

SourceLocation to_location(const Document& doc, Position p, Encoding enc) {
  int number = p.line < INT_MAX ? p.line + 1 : INT_MAX;  // past the end either way
  std::string_view line = line_of(doc, number);
  return {number, static_cast<int>(bytes_for(line, p.character, enc)) + 1};
}

// The token under the cursor; a cursor just after a token counts as on it, and where two
// tokens touch there the identifier wins. -1 when none.
int token_at(const Document& doc, SourceLocation loc) {
  auto first = std::lower_bound(doc.tokens.begin(), doc.tokens.end(), loc.line,
                                [](const Token& t, int line) { return t.loc.line < line; });
  int found = -1;
  for (auto it = first; it != doc.tokens.end() && it->loc.line == loc.line; ++it) {
    if (loc.col < it->loc.col || loc.col > it->loc.col + it->length) continue;
    if (found < 0 || it->kind == TokenKind::identifier) found = static_cast<int>(it - doc.tokens.begin());
  }
  return found;
}

// The last token that starts before the cursor; -1 when none.
int token_before(const Document& doc, SourceLocation loc) {
  int found = -1;
  for (std::size_t i = 0; i < doc.tokens.size(); ++i) {
    const SourceLocation& t = doc.tokens[i].loc;
    if (t.line > loc.line || (t.line == loc.line && t.col >= loc.col)) break;
    found = static_cast<int>(i);
  }
  return found;
}

bool is(const Document& doc, int i, TokenKind kind) {
  return i >= 0 && i < static_cast<int>(doc.tokens.size()) && doc.tokens[i].kind == kind;
}

// The drone named before the dot that token `dot` is, or "" when it is no `Drone.`.
std::string drone_at_dot(const Document& doc, int dot) {
  if (!is(doc, dot, TokenKind::dot) || !is(doc, dot - 1, TokenKind::identifier)) return "";
  return doc.tokens[dot - 1].text;
}

Range name_range(const Document& doc, SourceLocation loc, const std::string& name, Encoding enc) {
  std::string_view line = line_of(doc, loc.line);
  return {to_position(line, loc, enc), to_position(line, {loc.line, loc.col + static_cast<int>(name.size())}, enc)};
}

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

// The argument names of an action: the table's, else the catalog's own text.
std::vector<std::string> param_names(const fleet::ActionSpec& a, const fleet::CapabilityDoc* doc) {
  std::vector<std::string> names;
  if (doc) {
    for (const auto& p : doc->params) names.push_back(p.name);
    return names;
  }
  std::string text = a.params;
  for (std::size_t pos = 0; pos < text.size();) {
    std::size_t comma = text.find(',', pos);
    if (comma == std::string::npos) comma = text.size();
    std::string n = text.substr(pos, comma - pos);
    while (!n.empty() && (n.front() == ' ' || n.front() == '[')) n.erase(0, 1);
    while (!n.empty() && n.back() == ']') n.pop_back();
    if (!n.empty()) names.push_back(n);
    pos = comma + 1;
  }
  return names;
}

std::vector<std::string> signatures(const std::string& prefix, const fleet::ActionSpec& a) {
  std::vector<std::string> names = param_names(a, fleet::capability_doc(a.name));
  std::vector<std::string> out;
  for (int arity : a.arities) {
    std::vector<std::string> used(names.begin(), names.begin() + std::min<std::size_t>(arity, names.size()));
    out.push_back(prefix + a.name + "(" + join(used, ", ") + ")");
  }
  return out;
}

std::string capitalised(std::string s) {
  if (!s.empty() && s[0] >= 'a' && s[0] <= 'z') s[0] = static_cast<char>(s[0] - 'a' + 'A');
  return s;
}

std::string params_markdown(const fleet::CapabilityDoc& doc) {
  std::string md;
  for (const auto& p : doc.params)
    md += "- `" + p.name + "`: " + p.meaning + (p.unit.empty() ? "" : ", in " + p.unit) + "\n";
  return md.empty() ? "" : "\n" + md;
}

std::string capability_markdown(const std::string& drone, const fleet::DroneType& type, const std::string& name) {
  const fleet::ActionSpec* action = type.find_action(name);
  const fleet::PropertySpec* property = type.find_property(name);
  if (!action && !property) return "";
  const fleet::CapabilityDoc* doc = fleet::capability_doc(name);
  std::vector<std::string> lines =
      action ? signatures(drone + ".", *action) : std::vector<std::string>{drone + "." + name + "()"};
  std::vector<std::string> kinds;
  if (action) kinds.push_back(std::string(fleet::action_class_name(action->action_class)) + " action");
  if (property)
    kinds.push_back(std::string(property->type == fleet::ValueType::number ? "number" : "boolean") + " property");
  std::string md =
      "```eamos\n" + join(lines, "\n") + "\n```\n" + capitalised(join(kinds, " and ")) + " of `" + type.name + "`";
  if (doc) md += ": " + doc->summary + (property && !doc->unit.empty() ? ", in " + doc->unit : "");
  md += ".\n";
  if (action && doc) md += params_markdown(*doc);
  return md;
}

std::string type_markdown(const fleet::Fleet& fleet, const std::string& type_name) {
  fleet::DroneType t = fleet.type_for(type_name);
  std::vector<std::string> actions, properties;
  for (const auto& a : t.actions)
    if (!fleet::sensor_index(a.name, t.sensors)) actions.push_back(a.name);
  for (const auto& p : t.properties)
    if (!fleet::sensor_index(p.name, t.sensors)) properties.push_back(p.name);
  std::string sensors = t.sensors == 0   ? "none"
                        : t.sensors == 1 ? "Sensor1"
                        : t.sensors == 2 ? "Sensor1, Sensor2"
                                         : "Sensor1 … Sensor" + std::to_string(t.sensors);
  std::string origin = t.generic ? "the generic multirotor" : "described in `" + fleet.path + "`";
  return "`" + type_name + "`: " + origin + ", adapter `" + t.adapter +
         "`.\n\n- actions: " + (actions.empty() ? "none" : join(actions, ", ")) +
         "\n- properties: " + join(properties, ", ") + "\n- sensors: " + sensors + "\n";
}

std::string block_markdown(const lang::Function& f) {
  std::string what = f.name == "INIT"                  ? "The mission: it runs first, and the mission ends with it."
                     : f.block == lang::BlockKind::par ? "Parallel block: its statements start together; it ends "
                                                         "when all of them have ended."
                                                       : "Sequence block: its statements run one after another.";
  return "```eamos\nfunc " + f.name + "()\n```\n" + what + "\n";
}

std::string identifier_markdown(const Document& doc, const fleet::Fleet& fleet, int i) {
  const std::string& name = doc.tokens[i].text;
  const lang::Mission& m = doc.mission;
  std::string drone = drone_at_dot(doc, i - 1);
  if (!drone.empty()) {
    int d = m.find_drone(drone);
    return d < 0 ? "" : capability_markdown(drone, fleet.type_for(m.drones[d].type), name);
  }
  if (is(doc, i - 1, TokenKind::identifier) && is(doc, i - 2, TokenKind::kw_var))
    return "```eamos\nvar " + doc.tokens[i - 1].text + " " + name + "\n```\n" + type_markdown(fleet, name);
  if (int d = m.find_drone(name); d >= 0)
    return "```eamos\nvar " + name + " " + m.drones[d].type + "\n```\n" + type_markdown(fleet, m.drones[d].type);
  if (int f = m.find_function(name); f >= 0) return block_markdown(m.functions[f]);
  lang::ControlKind kind = lang::control_from_name(name);
  if (kind != lang::ControlKind::none)
    return "```eamos\n" + std::string(lang::control_usage(kind)) +
           "\n```\nControl structure: " + lang::control_meaning(kind) + ".\n";
  return "";
}

}  // namespace

json hover(const Document& doc, const fleet::Fleet& fleet, Position at, Encoding enc) {
  int i = token_at(doc, to_location(doc, at, enc));
  if (!is(doc, i, TokenKind::identifier)) return nullptr;
  std::string md = identifier_markdown(doc, fleet, i);
  if (md.empty()) return nullptr;
  return {{"contents", {{"kind", "markdown"}, {"value", md}}},
          {"range", to_json(token_range(doc, doc.tokens[i], enc))}};
}

json definition(const Document& doc, Position at, Encoding enc) {
  int i = token_at(doc, to_location(doc, at, enc));
  if (!is(doc, i, TokenKind::identifier) || is(doc, i - 1, TokenKind::dot)) return nullptr;
  const std::string& name = doc.tokens[i].text;
  const lang::Mission& m = doc.mission;
  SourceLocation loc;
  if (int d = m.find_drone(name); d >= 0)
    loc = m.drones[d].loc;
  else if (int f = m.find_function(name); f >= 0)
    loc = m.functions[f].loc;
  if (!loc.known()) return nullptr;
  return {{"uri", doc.uri}, {"range", to_json(name_range(doc, loc, name, enc))}};
}

namespace {

json item(const std::string& label, int kind, const std::string& detail, const std::string& markdown = "") {
  json j = {{"label", label}, {"kind", kind}, {"detail", detail}};
  if (!markdown.empty()) j["documentation"] = {{"kind", "markdown"}, {"value", markdown}};
  return j;
}

json capability_items(const Document& doc, const fleet::Fleet& fleet, const std::string& drone) {
  json items = json::array();
  int d = doc.mission.find_drone(drone);
  if (d < 0) return items;
  fleet::DroneType t = fleet.type_for(doc.mission.drones[d].type);
  for (const auto& a : t.actions)
    items.push_back(item(a.name, kItemMethod, join(signatures("", a), " | "), capability_markdown(drone, t, a.name)));
  for (const auto& p : t.properties)
    if (!t.find_action(p.name))
      items.push_back(item(p.name, kItemProperty,
                           p.name + "() " + (p.type == fleet::ValueType::number ? "number" : "boolean"),
                           capability_markdown(drone, t, p.name)));
  return items;
}

json general_items(const Document& doc) {
  json items = json::array();
  for (const auto& d : doc.mission.drones) items.push_back(item(d.name, kItemVariable, "var " + d.name + " " + d.type));
  for (const auto& f : doc.mission.functions)
    if (f.name != "INIT")
      items.push_back(item(f.name, kItemFunction, f.block == lang::BlockKind::par ? "PAR block" : "SEQ block"));
  for (int k = static_cast<int>(lang::ControlKind::If); k <= static_cast<int>(lang::ControlKind::DoWhileSync); ++k) {
    auto kind = static_cast<lang::ControlKind>(k);
    items.push_back(item(lang::control_name(kind), kItemKeyword, lang::control_usage(kind)));
  }
  for (const char* kw : {"async", "true", "false", "func", "var", "package"})
    items.push_back(item(kw, kItemKeyword, "keyword"));
  return items;
}

}  // namespace

json completion(const Document& doc, const fleet::Fleet& fleet, Position at, Encoding enc) {
  SourceLocation loc = to_location(doc, at, enc);
  int i = token_before(doc, loc);
  // A word being typed (the cursor inside or right after it) is what completion replaces.
  if (is(doc, i, TokenKind::identifier) && doc.tokens[i].loc.line == loc.line &&
      doc.tokens[i].loc.col + doc.tokens[i].length >= loc.col)
    --i;
  std::string drone = drone_at_dot(doc, i);
  json items = drone.empty() && !is(doc, i, TokenKind::dot) ? general_items(doc) : capability_items(doc, fleet, drone);
  return {{"isIncomplete", false}, {"items", items}};
}

namespace {

int token_starting(const Document& doc, SourceLocation loc) {
  for (std::size_t i = 0; i < doc.tokens.size(); ++i)
    if (doc.tokens[i].loc.line == loc.line && doc.tokens[i].loc.col == loc.col) return static_cast<int>(i);
  return -1;
}

// The last token of a function's body: its closing brace, or what comes before the next
// `func` when the body is not closed yet (the text is being typed).
int body_end(const Document& doc, int name) {
  int depth = 0, last = name;
  for (int i = name + 1; i < static_cast<int>(doc.tokens.size()); ++i) {
    TokenKind k = doc.tokens[i].kind;
    if (k == TokenKind::kw_func || k == TokenKind::kw_var) break;
    last = i;
    if (k == TokenKind::lbrace) ++depth;
    if (k == TokenKind::rbrace && --depth <= 0) break;
  }
  return last;
}

json symbol(const Document& doc, const std::string& name, const std::string& detail, int kind, int first, int last,
            int name_token, Encoding enc, bool hierarchical) {
  Range range{token_range(doc, doc.tokens[first], enc).start, token_range(doc, doc.tokens[last], enc).end};
  if (!hierarchical)
    return {{"name", name}, {"kind", kind}, {"location", {{"uri", doc.uri}, {"range", to_json(range)}}}};
  return {{"name", name},
          {"detail", detail},
          {"kind", kind},
          {"range", to_json(range)},
          {"selectionRange", to_json(token_range(doc, doc.tokens[name_token], enc))}};
}

}  // namespace

json document_symbols(const Document& doc, Encoding enc, bool hierarchical) {
  json out = json::array();
  for (const auto& d : doc.mission.drones) {
    int n = token_starting(doc, d.loc);
    if (n < 0) continue;
    int type = token_starting(doc, d.type_loc);
    out.push_back(symbol(doc, d.name, d.type, kSymbolVariable, is(doc, n - 1, TokenKind::kw_var) ? n - 1 : n,
                         type > n ? type : n, n, enc, hierarchical));
  }
  for (const auto& f : doc.mission.functions) {
    int n = token_starting(doc, f.loc);
    if (n < 0) continue;
    std::string detail = f.name == "INIT" ? "the mission" : f.block == lang::BlockKind::par ? "PAR block" : "SEQ block";
    out.push_back(symbol(doc, f.name, detail, kSymbolFunction, is(doc, n - 1, TokenKind::kw_func) ? n - 1 : n,
                         body_end(doc, n), n, enc, hierarchical));
  }
  return out;
}

}  // namespace eamos::lsp
