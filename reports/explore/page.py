"""The page's own script: every control and view gets its ``data-testid`` and keyboard.

Bokeh draws each widget and figure in a shadow root; this script (run on the document's
``document_ready`` event, and again every half second for controls made later, such as
another model's sliders) finds the hosts by their CSS class (``param-NAME``,
``view-NAME``), sets ``data-testid`` to that class, makes each control focusable
(``tabindex=0``) and moves it with the arrow keys (a slider by its step, up and right
raising it; a choice to the next option with down or right, the previous with up or left)
when it is focused itself (the app's outermost element says
``data-lm-suppress-shortcuts``: in Jupyter the notebook's own keys, arrows included, do
not take those meant for a control), and counts each view's redraws in
``data-version`` (its data sources' changes, after the next animation frame; the time of
the last in ``data-drawn-at``, milliseconds of ``performance.now()``; the views by name in
``window.__microcylViews``, for tests that read them without walking the page). Nothing
is loaded from anywhere.

Examples
--------
>>> "dataset.testid" in SCRIPT and "http" not in SCRIPT
True
"""

from __future__ import annotations

from bokeh.models import CustomJS

__all__ = ["SCRIPT", "page_script"]

SCRIPT = r"""
const docs = (window.Bokeh && Bokeh.documents) || [];
function model(name) {
  for (const d of docs) { const m = d.get_model_by_name(name); if (m) return m; }
  return null;
}
function hosts(root, out) {
  for (const el of root.querySelectorAll('[class*="param-"], [class*="view-"], *')) {
    for (const c of el.classList) {
      if (c.startsWith('param-') || c.startsWith('view-')) out.push([el, c]);
    }
    if (el.shadowRoot) hosts(el.shadowRoot, out);
  }
  return out;
}
function outermost(el) {
  while (el.getRootNode() instanceof ShadowRoot) el = el.getRootNode().host;
  return el;
}
function step(m, dir) {
  if (m.step !== undefined && m.start !== undefined) {
    const v = Math.min(m.end, Math.max(m.start, m.value + dir * m.step));
    m.value = Math.round(v / m.step) * m.step;
  } else if (m.options !== undefined) {
    const opts = m.options.map(o => Array.isArray(o) ? o[0] : o);
    const i = opts.indexOf(m.value);
    m.value = opts[Math.min(opts.length - 1, Math.max(0, i + dir))];
  } else if (m.active !== undefined) {
    m.active = dir > 0;
  }
}
function tag() {
  for (const [el, c] of hosts(document, [])) {
    if (el.dataset.testid === c) continue;
    el.dataset.testid = c;
    if (c.startsWith('param-')) {
      outermost(el).dataset.lmSuppressShortcuts = 'true';  // Jupyter's keys pass it by
      el.tabIndex = 0;
      el.addEventListener('keydown', e => {
        if (e.composedPath()[0] !== el) return;
        const m = model(c);
        const choice = m && m.options !== undefined;     // a list: down is the next one
        const dir = {ArrowRight: 1, ArrowLeft: -1, ArrowUp: choice ? -1 : 1,
                     ArrowDown: choice ? 1 : -1}[e.key];
        if (dir && m) { e.preventDefault(); step(m, dir); }
      });
    } else {
      el.dataset.version = '0';
      const name = c.slice(5);
      (window.__microcylViews = window.__microcylViews || {})[name] = el;
      for (const d of docs) {
        for (const m of d.all_models) {
          if (m.name && m.name.startsWith('src-' + name)) {
            m.change.connect(() => requestAnimationFrame(() => {
              el.dataset.version = String(Number(el.dataset.version) + 1);
              el.dataset.drawnAt = String(performance.now());
            }));
          }
        }
      }
    }
  }
}
tag();
if (!window.__microcylKeys) {
  window.__microcylKeys = true;
  window.addEventListener('keydown', () => { window.__microcylKeyAt = performance.now(); },
                          true);
}
if (!window.__microcylTag) { window.__microcylTag = setInterval(tag, 500); }
"""


def page_script() -> CustomJS:
    """The script as a Bokeh callback (``doc.js_on_event("document_ready", ...)``)."""
    return CustomJS(code=SCRIPT)
