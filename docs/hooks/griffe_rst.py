"""griffe extension for the API reference: the package's docstrings use reStructuredText roles
(``:class:`~fms_testbed.run.Results```) and double back-quotes, which Markdown would show
verbatim; turn them into Markdown code spans (mkdocstrings' cross-references where the target is
a full dotted path). Literal blocks (``Example::`` + indented block) become fenced code."""

from __future__ import annotations

import re
import textwrap

import griffe

_ROLE = re.compile(r":(?:class|func|meth|data|mod|attr|exc|obj):`(~?)([^`<]+?)(?:\s*<([^>]+)>)?`")


def _role(m: re.Match) -> str:
    short, target, explicit = m.group(1), m.group(2).strip(), m.group(3)
    target = (explicit or target).lstrip(".")
    shown = target.rsplit(".", 1)[-1] if short else target
    if target.startswith("fms_testbed.") and not any(p.startswith("_") for p in target.split(".")):
        # an optional autoref: a link where the target is documented, plain code elsewhere
        return f'<autoref identifier="{target}" optional><code>{shown}</code></autoref>'
    return f"`{shown}`"


def rst_to_markdown(text: str) -> str:
    """Roles → code spans or cross-references, ````x```` → ```x```, ``::`` blocks fenced."""
    text = _ROLE.sub(_role, text).replace("``", "`")
    lines, out, i = text.splitlines(), [], 0
    while i < len(lines):
        line = lines[i]
        if line.rstrip().endswith("::") and not line.strip().startswith(">>>"):
            head = line.rstrip()[:-2].rstrip()
            if head:
                out.append(head + ":")
            j, block = i + 1, []
            indent = len(line) - len(line.lstrip())
            while j < len(lines) and (not lines[j].strip()
                                      or len(lines[j]) - len(lines[j].lstrip()) > indent):
                block.append(lines[j])
                j += 1
            while block and not block[-1].strip():
                block.pop()
            if not block:
                i += 1
                continue
            pad = " " * indent
            code = textwrap.dedent("\n".join(block)).strip("\n")
            out += ["", pad + "```text", *[pad + c for c in code.splitlines()], pad + "```", ""]
            i = j
            continue
        out.append(line)
        i += 1
    return "\n".join(out)


class RstToMarkdown(griffe.Extension):
    """Convert every docstring once it is loaded."""

    def on_object(self, *, obj, **kwargs) -> None:  # noqa: D102 - griffe hook
        if obj.docstring is not None:
            obj.docstring.value = rst_to_markdown(obj.docstring.value)
