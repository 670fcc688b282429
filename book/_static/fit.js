// Scale each display equation that is wider than its column down to fit it (MathJax 3 has no
// automatic line breaking); undone and redone when the window is resized.  See fit.css.
(function () {
  function fit() {
    document.querySelectorAll('article.bd-article mjx-container[display="true"]').forEach(function (m) {
      m.style.fontSize = "";
      var room = m.parentElement.clientWidth, need = m.scrollWidth;
      if (need > room && room > 0) m.style.fontSize = Math.floor(1000 * room / need) / 10 + "%";
    });
  }
  function whenTypeset() {
    var mj = window.MathJax;
    if (mj && mj.startup && mj.startup.promise) mj.startup.promise.then(fit);
    else fit();
  }
  // Each table cell carries its column's header as data-label (shown by fit.css in a narrow window).
  function label() {
    document.querySelectorAll("article.bd-article table").forEach(function (t) {
      var heads = Array.prototype.map.call(t.querySelectorAll("thead th"), function (th) {
        return th.textContent.trim();
      });
      t.querySelectorAll("tbody tr").forEach(function (tr) {
        Array.prototype.forEach.call(tr.children, function (td, i) {
          if (heads[i]) td.setAttribute("data-label", heads[i]);
        });
      });
    });
  }
  window.addEventListener("DOMContentLoaded", label);
  window.addEventListener("load", whenTypeset);
  window.addEventListener("resize", fit);
})();
