#!/usr/bin/env python3
"""The house limits on the C++ sources: no file over 600 lines, no function over 80.

Reads every .cpp and .h under src/, include/, apps/ and tests/ (fixtures and the fuzz targets
among them) of the checkout holding this script, or of the folder given as the one argument.
Prints one line per breach, "<path>:<line>: ..." (a function's line is its opening brace's),
and exits 1 if there is any, else 0.

A function is a brace block opened at namespace or class level after a parameter list: its
length counts the lines from its opening brace to its closing one, both included (a signature
over several lines is not counted). Lambdas and blocks inside a function are part of it.
Comments, string and character literals (raw strings too) are skipped, so braces in them count
for nothing.
"""
import pathlib
import re
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 80
FOLDERS = ("src", "include", "apps", "tests")
SUFFIXES = (".cpp", ".h")


def code_only(text):
    """The text with comments and literals blanked (newlines kept, so line numbers stay)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^()\\ \n]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum())):  # 1'000 is a number
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def without_preprocessor(code):
    """Preprocessor lines (and their continuations) blanked."""
    lines = code.split("\n")
    continued = False
    for k, line in enumerate(lines):
        if continued or line.lstrip().startswith("#"):
            continued = line.rstrip().endswith("\\")
            lines[k] = ""
    return "\n".join(lines)


SCOPE_WORDS = re.compile(r"\b(namespace|extern)\b")
TYPE_WORDS = re.compile(r"\b(struct|class|union|enum)\b")


def kind_of_block(head):
    """What a '{' opens at namespace or class level, from the text since the last ; { or }."""
    head = " ".join(head.split())
    if SCOPE_WORDS.match(head) or head.startswith("extern"):
        return "namespace"
    if ")" not in head:
        return "class" if TYPE_WORDS.search(head) else "other"
    before_paren = head.split("(")[0]
    if "=" in before_paren or TYPE_WORDS.match(head):
        return "class" if TYPE_WORDS.match(head) and "=" not in before_paren else "other"
    return "function"


def function_name(head):
    head = " ".join(head.split())
    test = re.match(r"(TEST\w*)\s*\(([^)]*)\)", head)
    if test:
        return f"{test.group(1)}({test.group(2)})"
    m = re.search(r"([~\w:<>]+|operator\s*\S+)\s*\(", head)
    return m.group(1) if m else head[:40]


def long_functions(text):
    """(line, name, length) of each function over the limit."""
    code = without_preprocessor(code_only(text))
    found = []
    stack = []  # kinds of the open blocks
    head_start, line = 0, 1
    open_fn = None  # (line of '{', name, depth)
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            if all(k in ("namespace", "class") for k in stack):
                head = code[head_start:i]
                kind = kind_of_block(head)
                if kind == "function":
                    open_fn = (line, function_name(head), len(stack))
                stack.append(kind)
            else:
                stack.append("inner")
            head_start = i + 1
        elif c == "}":
            if stack:
                stack.pop()
            if open_fn and len(stack) == open_fn[2]:
                length = line - open_fn[0] + 1
                if length > MAX_FUNCTION_LINES:
                    found.append((open_fn[0], open_fn[1], length))
                open_fn = None
            head_start = i + 1
        elif c == ";" and all(k in ("namespace", "class") for k in stack):
            head_start = i + 1
        elif c == ":" and stack and stack[-1] == "class" and code[i - 1] != ":" and code[i + 1 : i + 2] != ":":
            head_start = i + 1  # `public:` and the like
    return found


def main(argv):
    root = pathlib.Path(argv[1]) if len(argv) > 1 else pathlib.Path(__file__).resolve().parent.parent
    breaches = []
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in SUFFIXES or not path.is_file():
                continue
            text = path.read_text(errors="replace")
            rel = path.relative_to(root)
            lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
            if lines > MAX_FILE_LINES:
                breaches.append(f"{rel}:1: file of {lines} lines (limit {MAX_FILE_LINES})")
            for at, name, length in long_functions(text):
                breaches.append(f"{rel}:{at}: function {name} of {length} lines (limit {MAX_FUNCTION_LINES})")
    for b in breaches:
        print(b)
    if breaches:
        print(f"house_limits: {len(breaches)} breach(es): split by concept (docs/development.md)", file=sys.stderr)
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
