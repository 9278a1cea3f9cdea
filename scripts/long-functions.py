#!/usr/bin/env python3
"""Lists the functions of C++ sources longer than a bound (60 lines), from the line of the
signature to the closing brace, lambdas counted in the function that holds them.

A function that is long because it is one thing (a table, a parser's switch) carries a
comment starting `// long:` with the reason, on one of the three lines above its signature;
such a function is not listed. Usage:

  scripts/long-functions.py [--max N] [--check] [--all] [--exclude PATH]... PATH...
                                                  (files or folders, their *.cpp and *.h)

--check: exit 1 when any function is listed (the ctest case `LongFunctionsHaveAReason`).
The scan is lexical (comments, strings and characters removed, braces matched), which is
reliable on this project's code: no macros open or close braces, no raw strings hold them.
"""
import argparse
import os
import re
import sys

SCOPE_KEYWORDS = re.compile(r'^(?:template\s*<.*>\s*)?(?:namespace\b|extern\s+"C"|(?:class|struct|union)\b)')
ENUM = re.compile(r'^(?:typedef\s+)?enum\b')
MARKER = re.compile(r'//\s*long:')


def strip(text):
    """`text` with comments, string and character literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i)
            j = n if j < 0 else j
            out.append(' ' * (j - i))
            i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == '_')):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(')' + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif c in '"\'':
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(' ')
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            j = min(j + 1, n)
            out.append(c + ' ' * (j - i - 2) + c if j - i >= 2 else ' ')
            i = j
        else:
            out.append(c)
            i += 1
    # preprocessor lines (with their continuations) are no part of any declaration
    return re.sub(r'(?m)^[ \t]*#(?:[^\n]*\\\n)*[^\n]*', lambda m: re.sub(r'[^\n]', ' ', m.group(0)), ''.join(out))


def is_function(header):
    """Whether the text before a `{` is a function's signature (or a lambda's, never at scope level)."""
    h = ' '.join(header.split())
    if not h or '(' not in h or h.startswith('#'):
        return False
    if re.match(r'^(?:if|for|while|switch|catch|do|else)\b', h):
        return False
    depth = 0
    for ch in h:  # an `=` outside parentheses makes it an initialiser, not a signature
        if ch in '(<[':
            depth += 1
        elif ch in ')>]':
            depth -= 1
        elif ch == '=' and depth == 0:
            return False
    return True


def in_initializer_list(header):
    """Whether a `{` after `header` opens a member's brace initialiser in a constructor's
    initialiser list (`Foo() : a_{1}`) rather than the constructor's body."""
    h = header.rstrip()
    if not h or not (h[-1].isalnum() or h[-1] in '_>'):
        return False
    depth = 0
    closed = False  # the parameter list has closed
    for i, ch in enumerate(h):
        if ch == '(':
            depth += 1
        elif ch == ')':
            depth -= 1
            closed = closed or depth == 0
        elif ch == ':' and depth == 0 and closed:
            if h[i - 1:i] != ':' and h[i + 1:i + 2] != ':':
                return True
    return False


def functions(text):
    """(first line, last line, name) of every function defined at namespace or class scope."""
    s = strip(text)
    found = []
    scopes = []  # per open brace: 'scope' (namespace, class), 'func', 'init' (a member's braces), 'other'
    start = 0  # where the current declaration's text begins
    line = 1
    line_at = []
    for ch in s:
        line_at.append(line)
        if ch == '\n':
            line += 1
    func_start = None
    for i, ch in enumerate(s):
        if ch == '{':
            in_scope = all(k in ('scope', 'init') for k in scopes)
            kind = 'other'
            if in_scope:
                header = s[start:i].strip()
                if SCOPE_KEYWORDS.match(header) and '(' not in header.split(':')[0]:
                    kind = 'scope'
                elif ENUM.match(header):
                    kind = 'other'
                elif in_initializer_list(header):
                    kind = 'init'
                elif is_function(header):
                    kind = 'func'
                    first = start + (len(s[start:i]) - len(s[start:i].lstrip()))
                    name = re.findall(r'([~\w:]+(?:operator\s*\S+?)?)\s*\(', header)
                    func_start = (line_at[first], name[0] if name else '?')
            scopes.append(kind)
            if kind != 'init':
                start = i + 1
        elif ch == '}':
            kind = scopes.pop() if scopes else 'scope'
            if kind == 'func' and all(k == 'scope' for k in scopes) and func_start:
                found.append((func_start[0], line_at[i], func_start[1]))
                func_start = None
            if kind != 'init' and all(k == 'scope' for k in scopes):
                start = i + 1
        elif ch == ';' and all(k == 'scope' for k in scopes):
            start = i + 1
        elif ch == ':' and all(k == 'scope' for k in scopes):
            # access specifiers (`public:`) end a declaration's text; `::` does not
            prev = s[start:i].strip()
            if prev in ('public', 'private', 'protected'):
                start = i + 1
    return found


def has_reason(lines, first):
    return any(MARKER.search(lines[k]) for k in range(max(0, first - 4), first))


def sources(paths):
    for p in paths:
        if os.path.isdir(p):
            for root, _, files in sorted(os.walk(p)):
                for f in sorted(files):
                    if f.endswith(('.cpp', '.h')):
                        yield os.path.join(root, f)
        else:
            yield p


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--max', type=int, default=60)
    ap.add_argument('--check', action='store_true')
    ap.add_argument('--all', action='store_true', help='list long functions with a reason too')
    ap.add_argument('--exclude', action='append', default=[], help='a file or folder not to scan (repeatable)')
    ap.add_argument('paths', nargs='+')
    a = ap.parse_args()
    listed = 0
    excluded = [os.path.normpath(e) for e in a.exclude]
    for path in sources(a.paths):
        norm = os.path.normpath(path)
        if any(norm == e or norm.startswith(e + os.sep) for e in excluded):
            continue
        with open(path, encoding='utf-8') as f:
            text = f.read()
        lines = text.split('\n')
        for first, last, name in functions(text):
            length = last - first + 1
            if length <= a.max:
                continue
            reason = has_reason(lines, first - 1)
            if reason and not a.all:
                continue
            listed += 0 if reason else 1
            tag = ' (long: reason given)' if reason else ''
            print(f'{path}:{first}: {name}: {length} lines{tag}')
    if a.check and listed:
        sys.stdout.flush()
        print(f'{listed} function(s) over {a.max} lines without a `// long:` reason above them; '
              'split them, or say why one is genuinely one thing', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
