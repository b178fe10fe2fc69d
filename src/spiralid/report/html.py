"""The one page template of spiralid's reports, and what goes into it.

``spiralid reproduce`` and ``spiralid study`` both write a self-contained
``report.html`` (figures embedded as PNG, no outside requests) from
:func:`page`, with tables from :func:`table` and figures from
:func:`figure`; the text summaries print the same tables as plain text.
"""

from __future__ import annotations

import base64
import html
import io

__all__ = ["figure", "page", "png", "table"]

_CSS = """
body { font-family: sans-serif; max-width: 980px; margin: 2em auto; color: #222;
       line-height: 1.45; padding: 0 1em; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.92em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: left; }
th { background: #eee; }
img { max-width: 100%; height: auto; }
code, pre { background: #f5f5f5; overflow-wrap: anywhere; }
pre { padding: 0.6em; white-space: pre-wrap; }
.table-wrap { max-width: 100%; overflow-x: auto; margin: 1em 0; }
.table-wrap table { margin: 0; }
.caption { font-size: 0.9em; color: #444; margin-bottom: 2em; }
"""

_PAGE = (
    "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
    "<title>{title}</title><style>{css}</style></head><body>{body}</body></html>"
)


def page(title: str, parts: list[str]) -> str:
    """The whole HTML document: `title` (escaped) and the body's `parts`
    (HTML already)."""
    return _PAGE.format(title=html.escape(title), css=_CSS, body="".join(parts))


def table(header: list[str], rows: list[list], fmt: str = "text") -> str:
    """`rows` under `header`, as aligned plain text or (``fmt="html"``) an
    HTML table with every cell escaped."""
    cells = [[str(c) for c in row] for row in rows]
    if fmt == "html":
        head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
        body = "".join(
            "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
            for row in cells
        )
        # In a box of the column's width that scrolls a table wider than it.
        return (
            f"<div class='table-wrap'><table><thead><tr>{head}</tr></thead>"
            f"<tbody>{body}</tbody></table></div>"
        )
    widths = [max([len(h), *(len(r[i]) for r in cells)]) for i, h in enumerate(header)]
    line = "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))
    out = [line, "  ".join("-" * w for w in widths)]
    out += [
        "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)) for r in cells
    ]
    return "\n".join(out)


def png(fig) -> bytes:
    """A Matplotlib figure as PNG bytes (the resolution of every saved one)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return buf.getvalue()


def figure(title: str, data: bytes, caption: str = "") -> str:
    """A heading, the embedded PNG `data` and its caption."""
    e = html.escape
    b64 = base64.b64encode(data).decode("ascii")
    out = f"<h3>{e(title)}</h3><img alt='{e(title)}' src='data:image/png;base64,{b64}'>"
    return out + (f"<p class='caption'>{e(caption)}</p>" if caption else "")
