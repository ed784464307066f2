#!/usr/bin/env python3
"""Writes the Python API reference (docs/reference/python.md) from the package's
docstrings: every name in clfractal.__all__, in that order, with its signature and its
numpydoc docstring (classes with their public methods and properties).

    PYTHONPATH=build/python build/python-venv/bin/python docs/gen/python_api.py > docs/reference/python.md
    ... docs/gen/python_api.py --check docs/reference/python.md
"""
import dataclasses
import inspect
import re
import sys

import page

HEADER = """# Python API

This page is generated from the docstrings of the `clfractal` package by
`docs/gen/python_api.py` (the ctest entry `docs_python_api` fails when it differs from them);
`help(clfractal.NAME)` shows the same text. Volumes are NumPy arrays in `(z, y, x)` order;
[From Python](../guide/python.md) explains installation, devices and dtypes.
"""


def numpydoc_to_markdown(doc):
    """numpydoc sections as markdown: underlined headings become bold lines, parameter
    lines `name : type` list items, `>>>` examples fenced code; the rest as written."""
    lines = inspect.cleandoc(doc).splitlines()
    out, i, section, in_code = [], 0, "", False
    while i < len(lines):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        google = re.fullmatch(r"(Attributes|Args|Arguments|Returns|Raises):", line.strip())
        if google and not line.startswith(" "):  # Google style: "Attributes:" and indented items
            section = "google"
            out += ["", f"**{google.group(1)}**", ""]
            i += 1
            continue
        if section == "google":
            item = re.match(r"    (\S[^:]*?): (.*)", line)
            if item and not line.startswith("     "):
                out.append(f"- `{item.group(1)}`: {item.group(2)}")
                i += 1
                continue
            if line.startswith("    "):
                out.append("  " + line.strip())
                i += 1
                continue
            if line.strip():
                section = ""
        if line.strip() and re.fullmatch(r"-{3,}", nxt.strip()):
            if in_code:
                out.append("```")
                in_code = False
            section = line.strip()
            out += ["", f"**{section}**", ""]
            i += 2
            continue
        if line.startswith(">>>") or (in_code and line.strip() and not line.startswith("    ")):
            if not in_code:
                out += ["", "```python"]
                in_code = True
            out.append(line)
        elif in_code and not line.strip():
            out.append("```")
            in_code = False
            out.append("")
        elif section in ("Parameters", "Returns", "Yields", "Raises", "Attributes", "Other Parameters") \
                and line.strip() and not line.startswith(" "):
            name, _, kind = line.partition(" : ")
            out.append(f"- `{name.strip()}`" + (f" ({kind.strip()})" if kind else "") + ":")
        elif line.startswith("    ") and section in ("Parameters", "Returns", "Yields", "Raises", "Attributes",
                                                    "Other Parameters"):
            out.append("  " + line.strip())
        else:
            out.append(line)
        i += 1
    if in_code:
        out.append("```")
    return "\n".join(out).strip() + "\n"


def value_comment(name):
    """The `#:` comment lines right above `name = ...` in the package's source."""
    import clfractal
    lines = inspect.getsource(clfractal).splitlines()
    for k, line in enumerate(lines):
        if re.match(rf"{re.escape(name)}\s*[:=]", line):
            comment = []
            while k > 0 and lines[k - 1].startswith("#:"):
                k -= 1
                comment.insert(0, lines[k][2:].strip())
            return (" ".join(comment) + "\n") if comment else ""
    return ""


def signature(obj):
    try:
        return str(inspect.signature(obj))
    except (TypeError, ValueError):
        return "(...)"


def document(name, obj):
    doc = inspect.getdoc(obj) or ""
    if inspect.isclass(obj):
        kind = "class"
        if dataclasses.is_dataclass(obj):
            sig = "(" + ", ".join(f.name for f in dataclasses.fields(obj)) + ")"
        elif issubclass(obj, tuple) and hasattr(obj, "_fields"):
            sig = "(" + ", ".join(obj._fields) + ")"
        else:
            sig = signature(obj)
    elif callable(obj):
        kind, sig = "def", signature(obj)
    else:  # a value: its `#:` comment in the module's source
        return f"\n### `{name}`\n\n`{name} = {obj!r}`\n\n" + value_comment(name)
    text = f"\n### `{name}`\n\n```python\n{kind} {name}{sig}\n```\n\n"
    text += numpydoc_to_markdown(doc) if doc else "(no docstring)\n"
    if inspect.isclass(obj):
        # Its own members, then those it takes from the package's private bases (_SlicePush).
        members = dict(obj.__dict__)
        for base in obj.__mro__[1:]:
            if base.__module__ == obj.__module__ and base.__name__.startswith("_"):
                members.update({k: v for k, v in base.__dict__.items() if k not in members})
        for member, value in members.items():
            if member.startswith("_") or not (inspect.getdoc(value) and (callable(value) or isinstance(value, property))):
                continue
            head = f"{name}.{member}" + ("" if isinstance(value, property) else signature(value))
            text += f"\n**`{head}`**\n\n" + numpydoc_to_markdown(inspect.getdoc(value))
    return text


def main():
    a = page.arguments(__doc__.splitlines()[0]).parse_args()
    import clfractal
    text = HEADER + f"\nVersion {clfractal.__version__}.\n"
    for name in clfractal.__all__:
        text += document(name, getattr(clfractal, name))
    return page.emit(text, a.check, "PYTHONPATH=build/python build/python-venv/bin/python docs/gen/python_api.py"
                     " > docs/reference/python.md")


if __name__ == "__main__":
    sys.exit(main())
