#include <sstream>

#include "diag/xml.h"
#include "graph/export.h"
#include "graph/palette.h"

namespace eamos::graph {

namespace {

// Triggers and control messages that cross from one drone to another: what the DEXes say
// over DDS, drawn apart from the arcs a drone follows on its own.
const char* kCrossDrone = "#7A0177";

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

std::string args_text(const std::vector<const lang::Expr*>& args) {
  std::string s;
  for (std::size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + lang::expr_text(*args[i]);
  return s;
}

std::string line_tag(SourceLocation loc) { return loc.known() ? "L" + std::to_string(loc.line) : ""; }

const char* meg_shape(MegKind k) {
  switch (k) {
    case MegKind::init:
    case MegKind::end: return "doublecircle";
    case MegKind::action: return "ellipse";
    case MegKind::fork: return "box";
    case MegKind::condition: return "diamond";
    case MegKind::terminal: return "box";
    case MegKind::pause: return "hexagon";
  }
  return "ellipse";
}

std::string arc_style(ArcKind kind, Branch branch, bool external) {
  std::string attrs;
  switch (kind) {
    case ArcKind::exec:
      attrs = external ? std::string("style=dashed, penwidth=1.8, color=\"") + kCrossDrone + "\"" : "style=solid";
      break;
    case ArcKind::back: attrs = "style=dotted, constraint=false"; break;
    case ArcKind::partner: attrs = "style=dashed, color=red, constraint=false"; break;
    case ArcKind::stop: attrs = "style=dashed, color=blue, constraint=false"; break;
  }
  std::string label = branch_name(branch);
  if (kind == ArcKind::partner && branch == Branch::any) label = "release";
  if (kind == ArcKind::stop) label = "stop";
  if (!label.empty()) attrs += ", label=\"" + label + "\", fontsize=9";
  return attrs;
}

void meg_node_line(std::ostringstream& out, const Compilation& c, const std::string& id,
                   const MegNode& n, int holder, bool external, const std::string& barrier = "") {
  std::string label = escape("n" + std::to_string(n.id) + "  " + meg_node_label(c, n));
  if (is_sync_point(n.kind) && holder >= 0) label += external ? " (arrival)" : " @" + c.drone_name(holder);
  if (!barrier.empty()) label += "\\n" + escape(barrier);
  std::string tag = line_tag(n.loc);
  if (!tag.empty() && n.kind != MegKind::end) label += "\\n" + tag;
  int colour_drone = n.drone >= 0 ? n.drone : holder;
  out << "  " << id << " [shape=" << meg_shape(n.kind) << ", label=\"" << label
      << "\", color=\"" << drone_colour(colour_drone) << "\"";
  // One style list: external copies dashed, forks rounded, terminals (small grey-filled
  // boxes, apart from forks and actions) filled.
  std::string style = external ? "dashed" : "";
  if (n.kind == MegKind::fork) style += std::string(style.empty() ? "" : ",") + "rounded";
  if (n.kind == MegKind::terminal) style += std::string(style.empty() ? "" : ",") + "filled";
  if (!style.empty()) out << ", style=\"" << style << "\"";
  if (external) out << ", fontcolor=\"#777777\"";
  if (n.kind == MegKind::terminal) out << ", fillcolor=\"#EEEEEE\", fontsize=9";
  out << "];\n";
}

/// A key to the picture, as one HTML-like table node beside the graph: node shapes, arc
/// styles and (`drones`) the drones' colours.
void legend(std::ostringstream& out, const Compilation& c) {
  out << "  subgraph cluster_legend {\n    label=\"legend\"; fontname=\"Helvetica\"; fontsize=10; "
         "color=\"#BBBBBB\";\n    legend [shape=plaintext, fontsize=9, label=<<table border=\"0\" "
         "cellspacing=\"2\" cellpadding=\"1\">\n";
  const char* rows[][2] = {{"ellipse", "action"},
                           {"diamond", "condition (control structure)"},
                           {"rounded box", "fork: start of a PAR block"},
                           {"grey box", "terminal: end of a block"},
                           {"double circle", "INIT / mission end"},
                           {"hexagon", "PauseFor"},
                           {"solid arrow", "trigger on the same drone"},
                           {"dashed purple arrow", "trigger across drones (DDS)"},
                           {"dotted arrow", "back arc: next iteration"},
                           {"dashed red arrow", "release of the partner terminal"},
                           {"dashed blue arrow", "stop watching"}};
  for (const auto& r : rows)
    out << "      <tr><td align=\"left\"><b>" << r[0] << "</b></td><td align=\"left\">" << r[1] << "</td></tr>\n";
  for (int d = 0; d < c.drone_count(); ++d)
    out << "      <tr><td align=\"left\"><font color=\"" << drone_colour(d) << "\"><b>&#9632; " << diag::xml_escape(c.drone_name(d))
        << "</b></font></td><td align=\"left\">its nodes</td></tr>\n";
  out << "    </table>>];\n  }\n";
}

}  // namespace

void append_meg_node_label(std::string& out, const Compilation& c, const MegNode& n) {
  switch (n.kind) {
    case MegKind::init: out += "INIT"; return;
    case MegKind::end: out += "end"; return;
    case MegKind::action:
      out += c.drone_name(n.drone);
      out += '.';
      out.append(n.name);
      out += '(';
      for (std::size_t i = 0; i < n.args.size(); ++i) {
        if (i) out += ", ";
        lang::append_expr_text(out, *n.args[i]);
      }
      out += ')';
      return;
    case MegKind::fork:
      out += "fork ";
      out.append(n.name);
      return;
    case MegKind::condition:
      out.append(n.name);
      out += ' ';
      lang::append_expr_text(out, *n.condition);
      if (n.control == lang::ControlKind::RepeatFor) out += " ×" + std::to_string(n.count);
      return;
    case MegKind::terminal:
      out += "T ";
      out.append(n.name);
      return;
    case MegKind::pause: {
      std::ostringstream s;
      s << "PauseFor(" << n.seconds << ")";
      out += s.str();
      return;
    }
  }
  out.append(n.name);
}

std::string meg_node_label(const Compilation& c, const MegNode& n) {
  std::string out;
  append_meg_node_label(out, c, n);
  return out;
}

std::string amt_dot(const Compilation& c) {
  std::ostringstream out;
  out << "digraph AMT {\n  rankdir=TB;\n  node [fontname=\"Helvetica\", fontsize=10];\n";
  for (const AmtNode& n : c.amt.nodes) {
    std::string label, shape = "box";
    switch (n.kind) {
      case AmtKind::init: label = "INIT"; shape = "doublecircle"; break;
      case AmtKind::seq: label = n.name; shape = "box"; break;
      case AmtKind::par: label = n.name; shape = "box3d"; break;
      case AmtKind::async: label = "async"; shape = "cds"; break;
      case AmtKind::control: label = std::string(n.name) + "\n" + lang::expr_text(*n.condition); shape = "diamond"; break;
      case AmtKind::action: label = c.drone_name(n.drone) + "." + std::string(n.name) + "(" + args_text(n.args) + ")"; shape = "ellipse"; break;
      case AmtKind::pause: {
        std::ostringstream s;
        s << "PauseFor(" << n.seconds << ")";
        label = s.str();
        shape = "hexagon";
        break;
      }
    }
    std::string tag = line_tag(n.loc);
    std::string text = escape(label);
    for (std::size_t p = text.find('\n'); p != std::string::npos; p = text.find('\n', p)) text.replace(p, 1, "\\n");
    out << "  a" << n.id << " [shape=" << shape << ", label=\"" << text
        << (tag.empty() ? "" : "\\n" + tag) << "\", color=\"" << drone_colour(n.drone) << "\"];\n";
  }
  for (const AmtNode& n : c.amt.nodes) {
    for (std::size_t i = 0; i < n.children.size(); ++i) {
      const AmtNode& child = c.amt.nodes[n.children[i]];
      std::string label;
      if (n.kind == AmtKind::seq || n.kind == AmtKind::init) label = std::to_string(i + 1);
      if (child.role != Role::none) label = role_name(child.role);
      out << "  a" << n.id << " -> a" << child.id;
      if (!label.empty()) out << " [label=\"" << label << "\", fontsize=9]";
      out << ";\n";
    }
  }
  out << "}\n";
  return out.str();
}

std::string meg_dot(const Compilation& c) {
  std::ostringstream out;
  out << "digraph MEG {\n  rankdir=TB;\n  node [fontname=\"Helvetica\", fontsize=10];\n";
  for (const MegNode& n : c.meg.nodes) meg_node_line(out, c, "n" + std::to_string(n.id), n, -1, false);
  for (const MegArc& a : c.meg.arcs) {
    // Across drones: both ends held by drones, and not the same one (sync points are cloned
    // onto each drone that needs them, so their arcs never cross).
    int from = c.meg.nodes[a.from].drone, to = c.meg.nodes[a.to].drone;
    bool cross = from >= 0 && to >= 0 && from != to;
    out << "  n" << a.from << " -> n" << a.to << " [" << arc_style(a.kind, a.branch, cross) << "];\n";
  }
  legend(out, c);
  out << "}\n";
  return out.str();
}

/// "Drone1, Drone2" or, past four, "Drone1 … Drone9 (9 drones)".
std::string drone_set_text(const Compilation& c, const std::vector<int>& set, int self) {
  std::vector<int> others;
  for (int d : set)
    if (d != self) others.push_back(d);
  if (others.size() > 4)
    return c.drone_name(others.front()) + " … " + c.drone_name(others.back()) + " (" +
           std::to_string(others.size()) + " drones)";
  std::string text;
  for (int d : others) text += (text.empty() ? "" : ", ") + c.drone_name(d);
  return text;
}

/// A sync point's barrier in words: whose arrival its clone waits for, whom this drone tells.
std::string barrier_text(const Compilation& c, const Mdg& g, const MdgNode& mn) {
  std::string text;
  if (mn.waits >= 0) text += "waits for " + drone_set_text(c, g.drone_sets[mn.waits], g.drone);
  if (mn.notify >= 0)
    text += (text.empty() ? "" : "\n") + std::string("tells ") + drone_set_text(c, g.drone_sets[mn.notify], g.drone);
  return text;
}

std::string mdg_dot(const Compilation& c, int drone) {
  const Mdg& g = c.mdgs[drone];
  std::ostringstream out;
  out << "digraph MDG_" << c.drone_name(drone)
      << " {\n  rankdir=TB;\n  node [fontname=\"Helvetica\", fontsize=10];\n"
      << "  label=\"MDG of " << c.drone_name(drone) << "\";\n";
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    const MdgNode& mn = g.nodes[i];
    meg_node_line(out, c, "m" + std::to_string(i), c.meg.nodes[mn.meg], mn.drone, !mn.internal,
                  barrier_text(c, g, mn));
  }
  for (const MdgArc& a : g.arcs)
    out << "  m" << a.from << " -> m" << a.to << " [" << arc_style(a.kind, a.branch, g.external(a))
        << "];\n";
  legend(out, c);
  out << "}\n";
  return out.str();
}

}  // namespace eamos::graph
