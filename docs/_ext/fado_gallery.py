"""Image scraper of the fado gallery.

``fado.plot`` draws on matplotlib's Agg canvas without pyplot (importing it changes no global
state), so sphinx-gallery's pyplot scraper does not see its figures. This scraper collects every
``matplotlib.figure.Figure`` bound to a name of the example's namespace after each code block,
once, in the order they appear.
"""

from __future__ import annotations

from typing import Any

from sphinx_gallery.scrapers import figure_rst


def scraper(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any]) -> str:
    from matplotlib.figure import Figure

    seen: set[int] = block_vars.setdefault("fado_seen_figures", set())
    paths = []
    for value in list(block_vars["example_globals"].values()):
        if isinstance(value, Figure) and id(value) not in seen:
            seen.add(id(value))
            path = next(block_vars["image_path_iterator"])
            value.savefig(path, dpi=90)
            paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
