#!/usr/bin/env python3
"""The size limits of C++ source files: no file over --max-file-lines lines and no function over
--max-function-lines lines (issue 62: a reader takes a function in at once).

A function counts from the first line of its signature (the first code line after the previous
declaration: a `template <...>` line included, comments before it not) to its closing brace; lambdas,
local classes and blocks inside it count in it. Functions are found by their braces on the text with
comments, string and character literals and preprocessor lines blanked: a `{` outside any function
whose head (the code since the previous `;`, `{` or `}`) has a `)` and no `=` outside parentheses and
does not open a namespace, class, struct, union or enum opens a function.

  check_code_size.py [--max-file-lines N] [--max-function-lines M] [--longest K] PATH...

PATH: a file or a folder (its *.cc and *.h, recursively). Prints one line per file or function over its
limit ("path:line: function NAME has L lines, limit M") and exits 1 if there is any; else prints a
summary of the longest function and file and exits 0.
"""
import argparse
import os
import re
import sys


def blank_non_code(text):
    """The text with comments, literals and preprocessor lines replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c == '#':  # a preprocessor line, with its continuations
            while i < n and text[i] != '\n':
                if text[i] == '\\' and i + 1 < n and text[i + 1] == '\n':
                    out.append(' \n')
                    i += 2
                    continue
                out.append(' ')
                i += 1
            continue
        if c == '\n':
            at_line_start = True
            out.append(c)
            i += 1
            continue
        if not c.isspace():
            at_line_start = False
        if text.startswith('//', i):
            while i < n and text[i] != '\n':
                out.append(' ')
                i += 1
            continue
        if text.startswith('/*', i):
            end = text.find('*/', i + 2)
            end = n if end < 0 else end + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:end]))
            i = end
            continue
        m = re.match(r'R"([^(\s]*)\(', text[i:i + 20])
        if m and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == '_')):
            end = text.find(')' + m.group(1) + '"', i)
            end = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:end]))
            i = end
            continue
        if c in '"\'':
            # A digit separator (1'000) is no literal.
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(' ')
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != '\n':
                j += 2 if text[j] == '\\' else 1
            out.append(' ' * (min(j, n - 1) - i + 1))
            i = j + 1
            continue
        out.append(c)
        i += 1
    return ''.join(out)


def outside_parens(head):
    """head with everything inside (), [] and <> of templates dropped (roughly: () and [] only)."""
    depth, kept = 0, []
    for ch in head:
        if ch in '([':
            depth += 1
        elif ch in ')]':
            depth -= 1
        elif depth == 0:
            kept.append(ch)
    return ''.join(kept)


def functions(text):
    """[(name, first line, last line)] of the functions defined in C++ source `text` (1-based lines)."""
    code = blank_non_code(text)
    line_of = []  # line number of each character
    line = 1
    for ch in code:
        line_of.append(line)
        if ch == '\n':
            line += 1
    found = []
    stack = []  # per open brace: 'function', 'scope' (namespace, type) or 'block'
    head_start = 0
    fn_start = None
    for i, ch in enumerate(code):
        if ch not in '{};':
            continue
        if ch == '{':
            in_function = 'function' in stack
            head = code[head_start:i]
            kind = 'block'
            if not in_function:
                plain = outside_parens(head)
                if re.search(r'\b(namespace|class|struct|union|enum)\b', plain) or re.search(r'extern\s*$', plain):
                    kind = 'scope'
                elif ')' in head and '=' not in plain.replace('operator=', '').replace('==', ''):
                    kind = 'function'
                    first = head_start + (len(head) - len(head.lstrip()))
                    name = re.findall(r'([~\w:]+(?:operator\W+)?)\s*\(', head)
                    fn_start = (name[0] if name else '?', line_of[first])
            stack.append(kind)
            head_start = i + 1
        elif ch == '}':
            kind = stack.pop() if stack else 'block'
            if kind == 'function' and 'function' not in stack:
                found.append((fn_start[0], fn_start[1], line_of[i]))
            head_start = i + 1
        else:
            head_start = i + 1
    return found


def sources(paths):
    for p in paths:
        if os.path.isdir(p):
            for root, _, files in os.walk(p):
                for f in sorted(files):
                    if f.endswith(('.cc', '.h')):
                        yield os.path.join(root, f)
        else:
            yield p


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--max-file-lines', type=int, default=1000)
    ap.add_argument('--max-function-lines', type=int, default=200)
    ap.add_argument('--longest', type=int, default=0, help='also list the N longest functions and files')
    ap.add_argument('paths', nargs='+')
    a = ap.parse_args()
    over, all_fns, all_files = [], [], []
    longest_fn, longest_file = ('', '', 0), ('', 0)
    for path in sources(a.paths):
        with open(path, encoding='utf-8') as f:
            text = f.read()
        lines = text.count('\n') + (0 if text.endswith('\n') or not text else 1)
        all_files.append((lines, path))
        if lines > longest_file[1]:
            longest_file = (path, lines)
        if lines > a.max_file_lines:
            over.append(f'{path}:1: file has {lines} lines, limit {a.max_file_lines}')
        for name, first, last in functions(text):
            length = last - first + 1
            all_fns.append((length, f'{path}:{first}', name))
            if length > longest_fn[2]:
                longest_fn = (path, name, length)
            if length > a.max_function_lines:
                over.append(f'{path}:{first}: function {name} has {length} lines, limit {a.max_function_lines}')
    if a.longest:
        for length, where, name in sorted(all_fns, reverse=True)[:a.longest]:
            print(f'{length:5d}  {name}  {where}')
        for lines, path in sorted(all_files, reverse=True)[:a.longest]:
            print(f'{lines:5d}  {path}')
    for o in over:
        print(o)
    if over:
        return 1
    print(f'code size: longest function {longest_fn[1]} ({longest_fn[0]}) {longest_fn[2]} lines '
          f'(limit {a.max_function_lines}), longest file {longest_file[0]} {longest_file[1]} lines '
          f'(limit {a.max_file_lines})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
