#!/usr/bin/env python3
"""Checks the component table of docs/architecture.md against the build.

For every component (a folder of src/ with a CMakeLists.txt) the table's column "may include
(its CMake link libraries)" must name exactly the eamos libraries its CMakeLists.txt links,
every one of them must be included somewhere in the component's sources, and no source may
include a header of a component outside that list. The components' links must form no cycle.
Every problem is reported, GCC style, and the exit status is 1 if there is any.

Usage: check_layers.py [SOURCE_ROOT]   (default: the repository holding this script)
"""
import os
import re
import sys

TABLE_HEADER = re.compile(r"^\|\s*folder\s*\|.*\|\s*may include \(its CMake link libraries\)\s*\|\s*$")
INCLUDE = re.compile(r'^\s*#\s*include\s*["<]([A-Za-z0-9_]+)/[^">]+[">]')
LINK_CALL = re.compile(r"target_link_libraries\s*\(([^)]*)\)", re.S)
SET_CALL = re.compile(r"\bset\s*\(\s*([A-Za-z0-9_]+)\s+([^)]*)\)", re.S)
SOURCE_SUFFIXES = (".h", ".hpp", ".cpp", ".cc", ".c", ".in")
NONE_WORDS = {"—", "-", ""}


def error(errors, where, what, fix):
    errors.append(f"{where}: error: {what}; {fix}")


def read_table(root, errors):
    """{component: (set of allowed components, line number)} from docs/architecture.md."""
    path = os.path.join(root, "docs", "architecture.md")
    rows, in_table = {}, False
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    for number, line in enumerate(lines, 1):
        if TABLE_HEADER.match(line):
            in_table = True
            continue
        if not in_table:
            continue
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if set(cells[0]) <= set("-: "):
            continue
        folder = re.fullmatch(r"`src/([A-Za-z0-9_]+)`", cells[0])
        if not folder or len(cells) != 3:
            error(errors, f"docs/architecture.md:{number}:1", f"row {line!r} is not | `src/NAME` | what | deps |",
                  "write the folder as `src/NAME` and the dependencies as a comma-separated list, or — for none")
            continue
        names = {n.strip().strip("`") for n in cells[2].split(",")} - NONE_WORDS
        rows[folder.group(1)] = (names, number)
    if not in_table:
        error(errors, f"docs/architecture.md:1:1", "no component table found",
              "keep the table whose last column is headed 'may include (its CMake link libraries)'")
    return rows


def cmake_links(path, components, self_name):
    """{component: line} of every eamos_<component> in the file's target_link_libraries calls."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    variables = {m.group(1): m.group(2) for m in SET_CALL.finditer(text)}
    links = {}
    for call in LINK_CALL.finditer(text):
        body = re.sub(r"\$\{([A-Za-z0-9_]+)\}", lambda m: variables.get(m.group(1), ""), call.group(1))
        line = text.count("\n", 0, call.start()) + 1
        for token in re.findall(r"\beamos_([A-Za-z0-9_]+)\b", body):
            if token in components and token != self_name:
                links.setdefault(token, line)
    return links


def source_includes(folder, components, self_name):
    """[(file, line, column, component)] of every include of another component's header."""
    found = []
    for dirpath, _, files in os.walk(folder):
        for name in sorted(files):
            if not name.endswith(SOURCE_SUFFIXES):
                continue
            path = os.path.join(dirpath, name)
            with open(path, encoding="utf-8", errors="replace") as f:
                for number, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if m and m.group(1) in components and m.group(1) != self_name:
                        found.append((path, number, line.index("#") + 1, m.group(1)))
    return found


def find_cycle(graph):
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                cycle = visit(nxt)
                if cycle:
                    return cycle
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node)
            if cycle:
                return cycle
    return None


def check(root):
    errors = []
    src = os.path.join(root, "src")
    components = sorted(d for d in os.listdir(src) if os.path.isfile(os.path.join(src, d, "CMakeLists.txt")))
    table = read_table(root, errors)
    for name, (allowed, number) in sorted(table.items()):
        if name not in components:
            error(errors, f"docs/architecture.md:{number}:1", f"src/{name} is in the table but is no component",
                  "remove its row, or give the folder a CMakeLists.txt")
        for dep in sorted(allowed - set(components)):
            error(errors, f"docs/architecture.md:{number}:1", f"src/{name} may include '{dep}', which is no component",
                  f"name folders of src/ only: {', '.join(components)}")
    for name in components:
        rel_cmake = f"src/{name}/CMakeLists.txt"
        if name not in table:
            error(errors, f"{rel_cmake}:1:1", f"src/{name} has no row in docs/architecture.md's component table",
                  "add a row: | `src/NAME` | what it is | the components it links |")
            continue
        allowed, number = table[name]
        links = cmake_links(os.path.join(root, rel_cmake), components, name)
        for dep in sorted(set(links) - allowed):
            error(errors, f"{rel_cmake}:{links[dep]}:1", f"src/{name} links eamos_{dep}, which docs/architecture.md:{number} does not allow",
                  f"add {dep} to its row if the dependency is meant, or remove the link")
        for dep in sorted(allowed - set(links)):
            error(errors, f"docs/architecture.md:{number}:1", f"src/{name} may include {dep}, but {rel_cmake} does not link eamos_{dep}",
                  f"link eamos_{dep} in {rel_cmake}, or remove {dep} from the row")
        included = set()
        for path, line, col, dep in source_includes(os.path.join(src, name), components, name):
            included.add(dep)
            if dep not in allowed:
                rel = os.path.relpath(path, root)
                error(errors, f"{rel}:{line}:{col}", f"src/{name} includes a header of src/{dep}, which docs/architecture.md:{number} does not allow ({', '.join(sorted(allowed)) or 'nothing'})",
                      f"remove the include, or make {dep} a dependency of {name} (its row and {rel_cmake})")
        for dep in sorted(set(links) & allowed - included):
            error(errors, f"{rel_cmake}:{links[dep]}:1", f"src/{name} links eamos_{dep} but includes none of its headers",
                  f"remove the link and {dep} from docs/architecture.md:{number}")
    cycle = find_cycle({name: allowed for name, (allowed, _) in table.items()})
    if cycle:
        error(errors, "docs/architecture.md:1:1", "the components depend on each other in a cycle: " + " → ".join(cycle),
              "dependencies point one way; move what both need into a component below both")
    return errors


def main(argv):
    root = argv[1] if len(argv) > 1 else os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    errors = check(root)
    for e in errors:
        print(e, file=sys.stderr)
    if errors:
        print(f"{len(errors)} layering error(s); the table is docs/architecture.md, 'Components and dependencies'", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
