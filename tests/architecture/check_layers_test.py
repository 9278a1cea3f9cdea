#!/usr/bin/env python3
"""check_layers.py on small made-up trees: it passes a tree that keeps its table and names
the file, the line and the forbidden component of each one that does not."""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_layers  # noqa: E402

TABLE = """# Architecture

| folder | component | may include (its CMake link libraries) |
| --- | --- | --- |
| `src/low` | the bottom | — |
| `src/mid` | the middle | low |
| `src/top` | the top | low, mid |

More text.
"""


class Tree:
    def __init__(self, table=TABLE):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name
        self.write("docs/architecture.md", table)
        self.component("low", "", {"low.h": "#pragma once\n"})
        self.component("mid", "eamos_low", {"mid.h": '#pragma once\n#include "low/low.h"\n'})
        self.component("top", "PUBLIC eamos_mid\n  PRIVATE eamos_low",
                       {"top.cpp": '#include "mid/mid.h"\n#include "low/low.h"\n#include <vector>\n'})

    def write(self, rel, text):
        path = os.path.join(self.root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)

    def component(self, name, links, files):
        cmake = f"add_library(eamos_{name} x.cpp)\n"
        if links:
            cmake += f"target_link_libraries(eamos_{name} {links})\n"
        self.write(f"src/{name}/CMakeLists.txt", cmake)
        for file, text in files.items():
            self.write(f"src/{name}/{file}", text)


class CheckLayers(unittest.TestCase):
    def tree(self, table=TABLE):
        made = Tree(table)
        self.addCleanup(made.dir.cleanup)
        return made

    def test_a_tree_that_keeps_its_table_passes(self):
        tree = self.tree()
        self.assertEqual(check_layers.check(tree.root), [])

    def test_an_include_of_a_component_not_in_the_row_is_named_with_its_file_and_line(self):
        tree = self.tree()
        tree.write("src/low/low.cpp", '#include "low/low.h"\n\n  #include "top/top.h"\n')
        errors = check_layers.check(tree.root)
        self.assertEqual(len(errors), 1, errors)
        self.assertTrue(errors[0].startswith("src/low/low.cpp:3:3: error: src/low includes a header of src/top"), errors[0])
        self.assertIn("remove the include", errors[0])

    def test_a_link_missing_from_the_table_and_a_row_not_linked_are_both_reported(self):
        tree = self.tree()
        tree.component("mid", "eamos_low eamos_top", {"mid.h": '#include "low/low.h"\n#include "top/top.h"\n'})
        tree.component("top", "eamos_mid", {"top.cpp": '#include "mid/mid.h"\n'})
        errors = "\n".join(check_layers.check(tree.root))
        self.assertIn("src/mid/CMakeLists.txt:2:1: error: src/mid links eamos_top, which docs/architecture.md:6 does not allow", errors)
        self.assertIn("src/mid/mid.h:2:1: error: src/mid includes a header of src/top", errors)
        self.assertIn("docs/architecture.md:7:1: error: src/top may include low, but src/top/CMakeLists.txt does not link eamos_low", errors)

    def test_a_link_whose_headers_are_never_included_is_reported(self):
        tree = self.tree()
        tree.component("top", "eamos_mid eamos_low", {"top.cpp": '#include "mid/mid.h"\n'})
        errors = check_layers.check(tree.root)
        self.assertEqual(errors, ["src/top/CMakeLists.txt:2:1: error: src/top links eamos_low but includes none of its "
                                  "headers; remove the link and low from docs/architecture.md:7"])

    def test_a_component_without_a_row_and_a_cycle_are_reported(self):
        tree = self.tree(TABLE.replace("| `src/low` | the bottom | — |", "| `src/low` | the bottom | top |"))
        tree.write("src/low/low.cpp", '#include "top/top.h"\n')
        tree.component("new", "", {})
        tree.component("low", "eamos_top", {"low.cpp": '#include "top/top.h"\n'})
        errors = "\n".join(check_layers.check(tree.root))
        self.assertIn("src/new/CMakeLists.txt:1:1: error: src/new has no row", errors)
        self.assertIn("error: the components depend on each other in a cycle: low → top → low", errors)

    def test_libraries_named_through_a_cmake_variable_count_as_links(self):
        tree = self.tree()
        tree.component("top", "", {"top.cpp": '#include "mid/mid.h"\n#include "low/low.h"\n'})
        tree.write("src/top/CMakeLists.txt", "set(libs eamos_low\n  eamos_mid)\nadd_library(eamos_top x.cpp)\n"
                                             "target_link_libraries(eamos_top PRIVATE ${libs})\n")
        self.assertEqual(check_layers.check(tree.root), [])


if __name__ == "__main__":
    unittest.main()
