#include <sstream>

#include "graph/export.h"

namespace eamos::graph {

namespace {

// Colour-blind-safe palette (Okabe–Ito), one colour per drone, cycling.
const char* drone_colour(int d) {
  static const char* palette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                  "#E69F00", "#56B4E9", "#F0E442", "#000000"};
  return d < 0 ? "#555555" : palette[d % 8];
}

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
    case MegKind::terminal: return "square";
    case MegKind::pause: return "hexagon";
  }
  return "ellipse";
}

std::string arc_style(ArcKind kind, Branch branch, bool external) {
  std::string attrs;
  switch (kind) {
    case ArcKind::exec: attrs = external ? "style=dashed" : "style=solid"; break;
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
                   const MegNode& n, int holder, bool external) {
  std::string label = escape("n" + std::to_string(n.id) + "  " + meg_node_label(c, n));
  if (is_sync_point(n.kind) && holder >= 0) label += " @" + c.drone_name(holder);
  std::string tag = line_tag(n.loc);
  if (!tag.empty() && n.kind != MegKind::end) label += "\\n" + tag;
  int colour_drone = n.drone >= 0 ? n.drone : holder;
  out << "  " << id << " [shape=" << meg_shape(n.kind) << ", label=\"" << label
      << "\", color=\"" << drone_colour(colour_drone) << "\"";
  if (external) out << ", style=dashed, fontcolor=\"#777777\"";
  if (n.kind == MegKind::fork) out << ", style=\"" << (external ? "dashed," : "") << "rounded\"";
  out << "];\n";
}

}  // namespace

std::string meg_node_label(const Compilation& c, const MegNode& n) {
  switch (n.kind) {
    case MegKind::init: return "INIT";
    case MegKind::end: return "end";
    case MegKind::action: return c.drone_name(n.drone) + "." + n.name + "(" + args_text(n.args) + ")";
    case MegKind::fork: return "fork " + n.name;
    case MegKind::condition: {
      std::string s = n.name + " " + lang::expr_text(*n.condition);
      if (n.control == lang::ControlKind::RepeatFor) s += " ×" + std::to_string(n.count);
      return s;
    }
    case MegKind::terminal: return "T " + n.name;
    case MegKind::pause: {
      std::ostringstream s;
      s << "PauseFor(" << n.seconds << ")";
      return s.str();
    }
  }
  return n.name;
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
      case AmtKind::control: label = n.name + "\n" + lang::expr_text(*n.condition); shape = "diamond"; break;
      case AmtKind::action: label = c.drone_name(n.drone) + "." + n.name + "(" + args_text(n.args) + ")"; shape = "ellipse"; break;
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
  for (const MegArc& a : c.meg.arcs)
    out << "  n" << a.from << " -> n" << a.to << " [" << arc_style(a.kind, a.branch, false) << "];\n";
  out << "}\n";
  return out.str();
}

std::string mdg_dot(const Compilation& c, int drone) {
  const Mdg& g = c.mdgs[drone];
  std::ostringstream out;
  out << "digraph MDG_" << c.drone_name(drone)
      << " {\n  rankdir=TB;\n  node [fontname=\"Helvetica\", fontsize=10];\n"
      << "  label=\"MDG of " << c.drone_name(drone) << "\";\n";
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    const MdgNode& mn = g.nodes[i];
    meg_node_line(out, c, "m" + std::to_string(i), c.meg.nodes[mn.meg], mn.drone, !mn.internal);
  }
  for (const MdgArc& a : g.arcs)
    out << "  m" << a.from << " -> m" << a.to << " [" << arc_style(a.kind, a.branch, g.external(a))
        << "];\n";
  out << "}\n";
  return out.str();
}

}  // namespace eamos::graph
