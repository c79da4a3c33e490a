"""The built site, checked in a real browser (headless Chromium, driven by Playwright).

    python docs/check.py [--site docs/_build/html] [--shots docs/screenshots]

Every page is opened from disk; a page fails when a request fails (an image, a script, a
style sheet), an image does not decode (naturalWidth 0), the browser logs an error, a
formula is left untypeset, MathJax cannot read it or its dollars are left in the text
(Markdown broke it apart), or a link inside the site points to a
missing page or anchor. The landing page and one demo page are saved as full-page
screenshots to look at.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path
from urllib.parse import unquote, urlparse

ROOT = Path(__file__).resolve().parents[1]
SHOTS = {"index.html": "landing.png", "demos/punch.html": "demo_punch.png"}
CHROMIUM = ("chromium", "chromium-browser", "google-chrome")


def browser_path() -> str:
    """Debian's chromium (`apt-get install chromium`)."""
    for name in CHROMIUM:
        found = shutil.which(name)
        if found:
            return found
    sys.exit("error: no Chromium found: install Debian's package 'chromium'")


# in the page: what did not load, and where every link inside the site points
PAGE_STATE = r"""() => ({
  broken_images: Array.from(document.images)
      .filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src),
  math: document.querySelectorAll('div.math, span.math').length,
  typeset: document.querySelectorAll('div.math mjx-container, span.math mjx-container')
      .length,
  math_errors: document.querySelectorAll('mjx-merror').length,
  // a formula Markdown broke apart (a line of it read as a list item, say) is no math
  // element: its dollars are left in the text
  stray_dollars: (() => {
    const main = document.querySelector('article') || document.body, found = [];
    const walk = document.createTreeWalker(main, NodeFilter.SHOW_TEXT);
    for (let n = walk.nextNode(); n; n = walk.nextNode()) {
      if (n.parentElement.closest('pre, code, .math, mjx-container, script, style')) continue;
      if (n.textContent.includes('$')) found.push(n.textContent.trim().slice(0, 60));
    }
    return found;
  })(),
  // a Markdown table that did not parse (a cell's unescaped "|" shifts its columns) is a
  // paragraph of pipes (its |---| row typeset as dashes)
  stray_tables: Array.from((document.querySelector('article') || document.body)
      .querySelectorAll('p')).map(p => p.textContent.trim())
      .filter(t => t.startsWith('|') && /\|\s*(---|—)/.test(t)).map(t => t.slice(0, 60)),
  links: Array.from(document.querySelectorAll('a[href]')).map(a => a.href)
      .filter(h => h.startsWith('file:')),
  ids: Array.from(document.querySelectorAll('[id]')).map(e => e.id),
})"""


def check_page(page, path: Path) -> tuple[list[str], dict]:
    """Load `path`; (problems, its state)."""
    problems: list[str] = []
    page.on("requestfailed", lambda r: problems.append(f"request failed: {r.url}"))
    page.on("console", lambda m: m.type == "error" and problems.append(f"console: {m.text}"))
    page.on("pageerror", lambda e: problems.append(f"script error: {e}"))
    page.goto(path.as_uri(), wait_until="load")
    if page.evaluate("() => document.querySelectorAll('div.math, span.math').length"):
        # MathJax typesets after the load event
        try:
            page.wait_for_function("() => window.MathJax && MathJax.startup && "
                                   "MathJax.startup.promise", timeout=20000)
            page.evaluate("() => MathJax.startup.promise")
        except Exception as err:  # Playwright's timeout: said with the rest, not a crash
            problems.append(f"MathJax did not start ({type(err).__name__})")
    state = page.evaluate(PAGE_STATE)
    problems += [f"image did not load: {src}" for src in state["broken_images"]]
    if state["typeset"] < state["math"]:
        problems.append(f"{state['math'] - state['typeset']} of {state['math']} formulas not "
                        "typeset (MathJax)")
    problems += [f"a formula left as text: {t!r}" for t in state["stray_dollars"]]
    problems += [f"a table left as text: {t!r}" for t in state["stray_tables"]]
    if state["math_errors"]:
        problems.append(f"{state['math_errors']} formulas MathJax could not read")
    return problems, state


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--site", type=Path, default=ROOT / "docs" / "_build" / "html")
    p.add_argument("--shots", type=Path, default=ROOT / "docs" / "screenshots")
    args = p.parse_args()
    from playwright.sync_api import sync_playwright

    pages = sorted(args.site.rglob("*.html"))
    pages = [q for q in pages if not q.relative_to(args.site).parts[0].startswith("_")]
    if not (args.site / "index.html").is_file():
        sys.exit(f"error: no site at {args.site} (make docs)")
    args.shots.mkdir(parents=True, exist_ok=True)
    failures, ids, links = [], {}, []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=browser_path(), args=["--no-sandbox"])
        for path in pages:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            problems, state = check_page(page, path)
            rel = path.relative_to(args.site).as_posix()
            failures += [f"{rel}: {m}" for m in problems]
            ids[path.resolve()] = set(state["ids"])
            links += [(rel, href) for href in state["links"]]
            if rel in SHOTS:
                page.screenshot(path=str(args.shots / SHOTS[rel]), full_page=True)
            page.close()
        browser.close()
    for rel, href in links:
        url = urlparse(href)
        target = Path(unquote(url.path)).resolve()
        if not target.exists():
            failures.append(f"{rel}: broken link to {target}")
        elif url.fragment and target.suffix == ".html" and target in ids \
                and url.fragment not in ids[target]:
            failures.append(f"{rel}: no anchor #{url.fragment} in {target.name}")
    for f in failures:
        print(f"docs check: {f}", file=sys.stderr)
    print(f"docs check: {len(pages)} pages, {len(links)} links inside the site, "
          f"{len(failures)} problems; screenshots in {args.shots}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
