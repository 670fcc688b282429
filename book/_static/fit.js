// Keeps every page within its column without breaking a word or a number (see fit.css):
// - a number with a hyphen in it (1e-16, 2-3) is kept on one line: Chromium breaks after that hyphen;
// - a code chip that is a tuple of two to four numbers ("(0.5, 0.5, 1.3)") is kept on one line;
// - a long identifier or code line gets <wbr> break points between its parts (after . _ / ( [ , = and
//   between two tokens of highlighted code), so a narrow column breaks it there and not mid-word; a link,
//   button or heading named by its words keeps them as its name (a browser names it with a space at each
//   break point: "perturbed_ normal_ surface", "s1_what_changes. ipynb");
// - in a table cell, values joined by slashes ("0.51/0.5/0.5") may break after a slash (a zero-width
//   space, which fit.css's nowrap turns off from 721 px; Chromium would break at a <wbr> even there), so
//   that a phone's narrow column wraps them; tables wider than their column are then scaled down to
//   fit, to no less than MIN_TABLE; a wider table scrolls sideways inside the theme's box around it
//   (fit.css), with a visible cue above it (p.fit-scroll-cue) that says so, and the box takes the
//   keyboard's focus (its arrow keys scroll it);
// - a display formula is broken again when its column's width changes: MathJax 4 breaks a display for
//   the width its column has when it is typeset (none inside a closed <details>, which has no width);
// - an in-line formula breaks after a relation or a binary operator, as TeX breaks one ("x =" ends a
//   line), and never between a sign and its operand ("(−" ending a line); MathJax 4 breaks before an
//   operator, MathML's default, which a display keeps.  (It also breaks at a
//   space, where TeX would not: a long product or tuple has no other place to break on a phone.)
// - every button of the article has a name of its own, so that a screen reader's list of them tells them
//   apart: a fold's toggle (sphinx-togglebutton names each "Toggle hidden content") is named by its fold's
//   title, a solution's by its exercise's too ("Solution: Exercise 2 (…)"); a name still shared (each
//   proof's "Proof", each code cell's "Copy to clipboard") gains where the control stands: the fold around
//   it, else its section's heading, and then, if need be, its place among the others ("2 of 3").
// - the main navigation's link to the page open says so (aria-current): the theme marks it by its look alone;
// - each exercise's title is a heading one level below its section's (sphinx-exercise writes a paragraph), so
//   that a screen reader can go from exercise to exercise;
// - a table's header cell with maths in it is named by its words and its formulas' MathML read as written
//   ("|h|", "h sub x", "ε̂"): a browser names a cell from its words alone, and §3's row headers were read
//   as ", , at" and nothing.
// The names, headings and break points are set once, when MathJax has typeset the page; the tables' fit and
// the displays' breaks are redone whenever the article changes size (window, sidebars, an opened <details>).
(function () {
  var MIN_TABLE = 0.75, LONG = 16;
  // Not inside maths (MathJax reads its source from these nodes), a piece already kept whole, or the
  // §4 simulator (its script rewrites its own text as it runs).
  var SKIP = "script, style, textarea, .math, mjx-container, .fit-whole, [data-symrender-sim]";

  function article() { return document.querySelector("article.bd-article"); }

  function textNodes(root, skip) {
    var out = [], walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
    for (var n = walker.nextNode(); n; n = walker.nextNode())
      if (!n.parentElement.closest(skip)) out.push(n);
    return out;
  }

  // Replace text node n by its pieces: strings, and [string] for a piece kept whole, with <wbr> where
  // a piece is null (the element around it named by its words keeps them as its name).
  var NAMED = "a, button, summary, [role=button], h1, h2, h3, h4, h5, h6, [role=heading], th";
  function splice(n, pieces) {
    var named = n.parentElement.closest(NAMED);
    if (pieces.indexOf(null) >= 0 && named && !named.hasAttribute("aria-label"))
      named.setAttribute("aria-label", named.textContent.replace(/\s+/g, " ").trim());
    var frag = document.createDocumentFragment();
    pieces.forEach(function (p) {
      if (p === null) frag.appendChild(document.createElement("wbr"));
      else if (typeof p === "string") { if (p) frag.appendChild(document.createTextNode(p)); }
      else { var s = document.createElement("span"); s.className = "fit-whole"; s.textContent = p[0];
             frag.appendChild(s); }
    });
    n.parentNode.replaceChild(frag, n);
  }

  var NUMBER = /\d[\d.,]*(?:[eE][-+]?\d+)?(?:-\d[\d.,]*(?:[eE][-+]?\d+)?)*/g;
  function keepNumbersWhole(root) {
    textNodes(root, SKIP).forEach(function (n) {
      var pieces = [], last = 0, m;
      NUMBER.lastIndex = 0;
      while ((m = NUMBER.exec(n.data))) {
        if (m[0].indexOf("-") < 0) continue;
        pieces.push(n.data.slice(last, m.index), [m[0]]);
        last = m.index + m[0].length;
      }
      if (pieces.length) { pieces.push(n.data.slice(last)); splice(n, pieces); }
    });
    root.querySelectorAll("code").forEach(function (c) {
      if (TUPLE.test(c.textContent)) c.classList.add("fit-whole");
    });
  }
  var NUM = "-?\\d[\\d.]*(?:e[-+]?\\d+)?", TUPLE = new RegExp("^\\(" + NUM + "(?:, " + NUM + "){1,3}\\)$", "i");

  // After . _ / = , ( [ between a letter (or closing bracket) and a letter: "renderer.<wbr>formulas".
  var JOINT = /([\p{L}\p{N}\])'"])([._\/=,(\[])(?=[\p{L}'"(\[])/gu;
  function breakLongWords(root) {
    textNodes(root, SKIP + ", pre").forEach(function (n) {
      var words = n.data.split(/(\s+)/), changed = false;
      var pieces = [];
      words.forEach(function (w) {
        if (w.length < LONG || /^\s/.test(w)) { pieces.push(w); return; }
        var parts = w.replace(JOINT, "$1$2\u0000").split("\u0000");
        if (parts.length > 1) changed = true;
        parts.forEach(function (p, i) { if (i) pieces.push(null); pieces.push(p); });
      });
      if (changed) splice(n, pieces);
    });
    // Highlighted code: a break point between two tokens with no blank between them ("np.|array(|x").
    root.querySelectorAll(".highlight pre > span").forEach(function (s) {
      var next = s.nextSibling;
      if (next && next.nodeType === 1 && next.tagName === "SPAN" && /\S$/.test(s.textContent) && /^\S/.test(next.textContent))
        s.parentNode.insertBefore(document.createElement("wbr"), next);
    });
  }

  // Table cells: values joined by slashes ("0.51/0.5/0.5", "1.2e+03/7.8e+02") in a span.fit-slashes, with a
  // break point (a zero-width space) after each slash, which fit.css turns off from 721 px.
  var SLASHED = /[^\s\/]*\d(?:\/\d[^\s\/]*)+/g;
  function breakTableCells(root) {
    root.querySelectorAll("td, th").forEach(function (cell) {
      textNodes(cell, SKIP).forEach(function (n) {
        var frag = document.createDocumentFragment(), last = 0, m;
        SLASHED.lastIndex = 0;
        while ((m = SLASHED.exec(n.data))) {
          frag.append(n.data.slice(last, m.index));
          var s = document.createElement("span");
          s.className = "fit-slashes"; s.textContent = m[0].replace(/\//g, "/\u200b");
          frag.append(s);
          last = m.index + m[0].length;
        }
        if (last) { frag.append(n.data.slice(last)); n.parentNode.replaceChild(frag, n); }
      });
    });
  }

  // A table that still scrolls sideways says so just above it, and its box is focusable; one that fits
  // has neither.
  var CUE = "Wider than the page: scroll the table sideways\u00a0\u2192";
  function cue(t) {
    var box = t.closest(".pst-scrollable-table-container") || t;
    var wide = box.scrollWidth > box.clientWidth + 1;
    var prev = box.previousElementSibling, has = !!(prev && prev.classList.contains("fit-scroll-cue"));
    if (wide && !has) {
      var p = document.createElement("p");
      p.className = "fit-scroll-cue"; p.textContent = CUE; p.setAttribute("aria-hidden", "true");
      box.parentNode.insertBefore(p, box);
    } else if (!wide && has) prev.remove();
    if (wide) box.setAttribute("tabindex", "0"); else if (box.getAttribute("tabindex") === "0") box.removeAttribute("tabindex");
  }

  // Each display formula typeset for its column's present width: those whose column (the element
  // around the formula) has another width than when they were last broken are typeset again, at that
  // width.  `broken` maps each of MathJax's math items to that width (0: it had none).
  var broken = new WeakMap();
  function rebreak(root, record) {
    var mj = window.MathJax, doc = mj && mj.startup && mj.startup.document;
    if (!doc || !doc.getMathItemsWithin) return;
    doc.getMathItemsWithin(root).forEach(function (item) {
      var box = item.display && item.typesetRoot && item.typesetRoot.parentNode;
      var width = box ? box.clientWidth : 0;
      if (!box || broken.get(item) === width || (!record && !width)) return;
      broken.set(item, width);
      if (record) return;
      var m = doc.outputJax.getMetricsFor(box, true);
      item.setMetrics(m.em, m.ex, m.containerWidth, m.scale);
      item.rerender(doc);
    });
  }

  // Before MathJax starts (its script is deferred; this one is not): its TeX input's last step marks each
  // operator of an in-line formula that follows an operand, but one whose break side is given, to break
  // after itself; a sign (the minus of "(−sin θ", of "= −1") not to break at all, and a fence is left as it is.
  var config = window.MathJax;
  if (config && !config.startup) config.startup = { ready: function () {
    MathJax.startup.defaultReady();
    MathJax.startup.document.inputJax[0].postFilters.add(function (args) {
      if (args.math.display) return;
      var CLASS = MathJax._.core.MmlTree.MmlNode.TEXCLASS;
      args.data.root.walkTree(function (node) {
        if (!node.isKind("mo") || node.attributes.hasExplicit("linebreakstyle") || node.texClass === CLASS.OPEN
            || node.texClass === CLASS.CLOSE) return;
        var siblings = node.parent ? node.parent.childNodes : [], prev = siblings[siblings.indexOf(node) - 1];
        if (prev && (!prev.isKind("mo") || prev.texClass === CLASS.CLOSE || prev.texClass === CLASS.ORD))
          node.attributes.set("linebreakstyle", "after");
        else node.attributes.set("linebreak", "nobreak");       // a sign, kept with its operand
      });
    });
  } };

  var typeset = false;      // MathJax has typeset the page, and `broken` holds its displays' widths
  function fit() {
    var root = article();
    if (!root) return;
    if (typeset) rebreak(root, false);
    root.querySelectorAll("table").forEach(function (t) {
      t.style.fontSize = "";
      var space = t.parentElement.clientWidth, need = t.getBoundingClientRect().width, scale = 1;
      // The cells' padding does not scale with the font: a few steps, each by the remaining excess.
      for (var k = 0; k < 8 && space > 0 && need > space + 0.5 && scale > MIN_TABLE; k++) {
        scale = Math.max(MIN_TABLE, scale * space / need);
        t.style.fontSize = 100 * scale + "%";
        need = t.getBoundingClientRect().width;
      }
      cue(t);
    });
    if (typeset) document.documentElement.setAttribute("data-fit", "done");     // for the browser tests
  }

  function nameControls(root) {
    // The words shown (a folded code cell's summary holds "Show …" and "Hide …", one of them shown).
    function text(el) { return el ? (el.innerText || el.textContent).replace(/\s+/g, " ").replace(/\s*#$/, "").trim() : ""; }
    function name(c) { return c.getAttribute("aria-label") || text(c); }
    root.querySelectorAll(".toggle-button").forEach(function (button) {
      var title = text(button.closest(".admonition-title")), fold = button.closest(".admonition");
      for (var e = fold; e && fold.classList.contains("solution"); e = e.previousElementSibling)
        if (e.classList.contains("exercise")) { title += ": " + text(e.querySelector(".admonition-title")); break; }
      if (title) button.setAttribute("aria-label", title);
    });
    function apart(more) {        // each name shared by several controls, extended by more(control, i, n)
      var by = {};
      root.querySelectorAll("button, summary").forEach(function (c) { (by[name(c)] = by[name(c)] || []).push(c); });
      Object.keys(by).forEach(function (n) {
        if (by[n].length > 1) by[n].forEach(function (c, i) {
          var extra = more(c, i, by[n].length);
          if (c.querySelector(":scope > .collapsed")) { c.dataset.context = (c.dataset.context || "") + extra; relabel(c); }
          else c.setAttribute("aria-label", n + extra);
        });
      });
    }
    apart(function (c) {
      // A fold that follows its theorem (a proof): the theorem's title.  Else the fold around it (by its
      // toggle's name, if it has one; not a folded code cell's, titled "Show code cell source"), else its section.
      var own = c.matches("summary") || c.closest(".admonition-title") ? c.closest("details, .admonition") : null;
      var item = own && own.previousElementSibling;
      if (item && item.matches(".theorem")) return ": " + text(item.querySelector(".admonition-title"));
      var fold = (own ? own.parentElement : c).closest("details:not(.hide), .admonition:not(.hide)");
      var title = fold && fold.querySelector(":scope > summary, :scope > .admonition-title");
      var toggle = title && title.querySelector(".toggle-button");
      if (title) return ": " + ((toggle && toggle.getAttribute("aria-label")) || text(title));
      var section = c.closest("section");
      return section ? ": " + text(section.querySelector("h1, h2, h3, h4")) : "";
    });
    apart(function (c, i, n) { return " (" + (i + 1) + " of " + n + ")"; });
  }

  // A figure, named by its number ("Fig. 7"): a screen reader says "figure, Fig. 7", then reads the image's
  // alt text and the caption (Chromium names a <figure> by nothing, not by its <figcaption>).
  function figureNames(root) {
    root.querySelectorAll("figure[id]").forEach(function (figure) {
      var number = figure.querySelector("figcaption .caption-number");
      if (!number) return;
      number.id = figure.id + "-number";
      figure.setAttribute("aria-labelledby", number.id);
    });
  }

  // An exercise's or a theorem's title, a heading one level below its section's: a screen reader goes from
  // heading to heading.
  function titleHeadings(root) {
    root.querySelectorAll(".exercise > .admonition-title, .theorem > .admonition-title").forEach(function (title) {
      var section = title.closest("section"), heading = section && section.querySelector("h1, h2, h3, h4, h5");
      title.setAttribute("role", "heading");
      title.setAttribute("aria-level", String(heading ? Number(heading.tagName[1]) + 1 : 3));
    });
  }

  // A formula's MathML in words a screen reader reads as it is written: a subscript after "sub" ("h sub x",
  // not "hx"), an accent over a letter as the letter's combining mark ("ε̂", not "ε^"), the rest as its text.
  var ACCENTS = { "^": "\u0302", "~": "\u0303", "\u00af": "\u0304", "\u02d9": "\u0307", "\u2192": "\u20d7" };
  function spoken(node) {
    var kids = Array.prototype.map.call(node.children, spoken);
    if (!kids.length) return node.textContent;
    if (node.localName === "msub" && kids.length === 2) return kids[0] + " sub " + kids[1];
    var accent = node.localName === "mover" && kids.length === 2 && ACCENTS[kids[1].trim()];
    return accent ? kids[0] + accent : kids.join("");
  }

  function nameHeaderCells(root) {
    root.querySelectorAll("th").forEach(function (th) {
      if (!th.querySelector("mjx-assistive-mml")) return;
      var copy = th.cloneNode(true);
      copy.querySelectorAll("mjx-container").forEach(function (m) {
        var mml = m.querySelector("mjx-assistive-mml");
        m.replaceWith(mml ? spoken(mml) : "");
      });
      th.setAttribute("aria-label", copy.textContent.replace(/\s+/g, " ").trim());
    });
  }

  // A folded code cell's summary: its name begins with the words it shows as the fold opens and closes.
  function relabel(summary) {
    var shown = summary.querySelector(summary.parentElement.open ? ":scope > .expanded" : ":scope > .collapsed");
    summary.setAttribute("aria-label", shown.textContent.trim() + summary.dataset.context);
  }
  document.addEventListener("toggle", function (e) {
    var summary = e.target.querySelector && e.target.querySelector(":scope > summary[data-context]");
    if (summary) relabel(summary);
  }, true);

  // Once MathJax has typeset the page (its source text is then out of the way): the controls' names, break
  // points, the widths the displays were broken for, then the tables.
  function whenTypeset() {
    var mj = window.MathJax, root = article();
    function done() {
      if (root) { nameControls(root); titleHeadings(root); figureNames(root); nameHeaderCells(root); keepNumbersWhole(root); breakLongWords(root); breakTableCells(root); rebreak(root, true); }
      typeset = true;
      fit();
    }
    if (mj && mj.startup && mj.startup.promise) mj.startup.promise.then(done);
    else done();
  }

  window.addEventListener("load", whenTypeset);
  window.addEventListener("load", function () {
    document.querySelectorAll(".bd-docs-nav a.current").forEach(function (a) { a.setAttribute("aria-current", "page"); });
  });
  // Whenever the article changes size: the window resized, a sidebar slid in or out (the column
  // settles after the resize event), a <details> opened (its maths and tables have a width only now).
  // Refitted in the next frame, not in the observer's callback: a change of size there would be a
  // "ResizeObserver loop" error.
  var pending = 0;
  window.addEventListener("load", function () {
    var root = article();
    if (root && window.ResizeObserver) new ResizeObserver(function () {
      cancelAnimationFrame(pending);
      pending = requestAnimationFrame(fit);
    }).observe(root);
  });
  document.addEventListener("toggle", fit, true);
})();
