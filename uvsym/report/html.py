"""``report.md`` -> ``report.html``: one self-contained file, the math rendered offline as MathML.

The Markdown is the source (GitHub renders it); the HTML is the same text for reading anywhere
without a network: ``$$...$$`` and ``$...$`` become MathML (latex2mathml; browsers draw MathML
natively), local SVG figures are embedded as data URIs, and the style sheet is inline. Links
to other files (the generated C, say) stay relative links. The same Markdown gives the same
bytes.
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

import markdown
from latex2mathml.converter import convert

from uvsym.errors import UvsymError

__all__ = ["markdown_to_html", "write_html"]

_STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, "Noto Sans CJK SC", "Source Han Sans SC",
       "PingFang SC", "Microsoft YaHei", sans-serif; line-height: 1.5;
       max-width: 60rem; margin: 2rem auto; padding: 0 1rem; color: #1f2328; }
table { border-collapse: collapse; margin: 1rem 0; display: block; overflow-x: auto; }
th, td { border: 1px solid #d0d7de; padding: 0.25rem 0.6rem; text-align: left; vertical-align: top; }
th { background: #f6f8fa; }
code { background: #f6f8fa; padding: 0.1rem 0.3rem; border-radius: 4px; font-size: 90%; }
math[display="block"] { display: block; overflow-x: auto; margin: 1rem 0; }
mtable.bracket { border-left: 1.5px solid; border-right: 1.5px solid; padding: 0.1em 0.35em;
                 background: linear-gradient(currentColor, currentColor) top left / 0.35em 1.5px no-repeat,
                             linear-gradient(currentColor, currentColor) bottom left / 0.35em 1.5px no-repeat,
                             linear-gradient(currentColor, currentColor) top right / 0.35em 1.5px no-repeat,
                             linear-gradient(currentColor, currentColor) bottom right / 0.35em 1.5px no-repeat; }
mtable.paren { border-left: 1.5px solid; border-right: 1.5px solid; border-radius: 0.6em / 50%; padding: 0.1em 0.4em; }
img { max-width: 100%; }
details { margin: 1rem 0; }
"""

# code spans are matched first so that a $ inside them is left alone
_TOKENS = re.compile(r"(?P<code>`[^`\n]*`)|\$\$(?P<block>.+?)\$\$|(?<![\\$])\$(?P<inline>[^$\n]+?)\$", re.DOTALL)
# a matrix's brackets are drawn by CSS around the table: stretchy <mo> needs a math font
_FENCE = '<mo stretchy="true" fence="true" form="{}">'
_FENCED_TABLE = re.compile(re.escape(_FENCE.format("prefix")) + r"(?P<open>[\[(])</mo><mtable>"
                           r"(?P<rows>(?:(?!</mtable>).)*)</mtable>"
                           + re.escape(_FENCE.format("postfix")) + r"[\])]</mo>")
_IMAGE = re.compile(r'<img alt="(?P<alt>[^"]*)" src="(?P<src>[^":]+\.svg)"\s*/?>')


def _mathml(tex: str, display: str) -> str:
    # bracketed matrices as \left[ ... \right], so that the brackets stretch in MathML Core
    for environment, left, right in (("bmatrix", "[", "]"), ("pmatrix", "(", ")")):
        tex = tex.replace(rf"\begin{{{environment}}}", rf"\left{left}\begin{{matrix}}")
        tex = tex.replace(rf"\end{{{environment}}}", rf"\end{{matrix}}\right{right}")
    try:
        mathml = convert(tex.strip(), display=display)
    except Exception as exc:  # latex2mathml raises plain exceptions for TeX it does not know
        raise UvsymError(f"cannot render the formula {tex.strip()[:80]!r} as MathML: {exc}") from exc
    return _FENCED_TABLE.sub(lambda m: f'<mtable class="{"bracket" if m.group("open") == "[" else "paren"}">'
                             f'{m.group("rows")}</mtable>', mathml)


def markdown_to_html(text: str, title: str, folder: Path) -> str:
    """The HTML page of Markdown ``text``; SVG images are read from ``folder`` and embedded.

    Raises UvsymError for a formula latex2mathml cannot render or an image that is missing.
    """
    formulas: list[str] = []

    def stash(match: re.Match) -> str:
        if match.group("code"):
            return match.group("code")
        display = "block" if match.group("block") is not None else "inline"
        formulas.append(_mathml(match.group("block") or match.group("inline"), display))
        return f"UVSYMMATH{len(formulas) - 1}X"

    source = _TOKENS.sub(stash, text).replace("<details>", '<details markdown="1">')
    body = markdown.markdown(source, extensions=["tables", "fenced_code", "md_in_html"], output_format="html")
    body = re.sub(r"<p>UVSYMMATH(\d+)X</p>", lambda m: formulas[int(m.group(1))], body)
    body = re.sub(r"UVSYMMATH(\d+)X", lambda m: formulas[int(m.group(1))], body)

    def embed(match: re.Match) -> str:
        path = folder / match.group("src")
        if not path.is_file():
            raise UvsymError(f"the report refers to {match.group('src')}, which is not in {folder}")
        data = base64.b64encode(path.read_bytes()).decode("ascii")
        return f'<img alt="{match.group("alt")}" src="data:image/svg+xml;base64,{data}">'

    body = _IMAGE.sub(embed, body)
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f"<title>{html.escape(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n{body}\n</body>\n</html>\n")


def write_html(folder: Path) -> Path:
    """Write ``folder/report.html`` from ``folder/report.md``; returns its path."""
    folder = Path(folder)
    text = (folder / "report.md").read_text()
    heading = re.search(r"^# (.+)$", text, re.MULTILINE)
    target = folder / "report.html"
    target.write_text(markdown_to_html(text, heading.group(1) if heading else folder.name, folder))
    return target
