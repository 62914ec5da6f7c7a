// tfloc site: sort any table by a click on its header, filter rows by matcher family. No network.
(function () {
  "use strict";
  function key(cell) {
    if (!cell) return null;
    var v = cell.getAttribute("data-v");
    if (v === null) v = cell.textContent.trim();
    if (v === "" || v === "nan") return null;
    var n = Number(v);
    return isNaN(n) ? v.toLowerCase() : n;
  }
  function sortBy(table, col, th) {
    var body = table.tBodies[0];
    var dir = th.getAttribute("aria-sort") === "descending" ? "ascending" :
      th.getAttribute("aria-sort") === "ascending" ? "descending" :
      (th.getAttribute("data-first") || "descending");
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = key(a.cells[col]), y = key(b.cells[col]);
      if (x === null && y === null) return 0;
      if (x === null) return 1;
      if (y === null) return -1;
      var c = (typeof x === "number" && typeof y === "number") ? x - y : String(x).localeCompare(String(y));
      return dir === "ascending" ? c : -c;
    });
    rows.forEach(function (r) { body.appendChild(r); });
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (h) { h.removeAttribute("aria-sort"); });
    th.setAttribute("aria-sort", dir);
  }
  function filter() {
    var on = {};
    document.querySelectorAll("fieldset.filters input").forEach(function (i) { on[i.value] = i.checked; });
    document.querySelectorAll("tr[data-kind]").forEach(function (r) {
      var show = on[r.getAttribute("data-kind")] !== false && on[r.getAttribute("data-origin")] !== false;
      if (show) r.removeAttribute("hidden"); else r.setAttribute("hidden", "");
    });
  }
  document.querySelectorAll("table.sortable").forEach(function (table) {
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th, col) {
      var b = th.querySelector("button");
      if (b) b.addEventListener("click", function () { sortBy(table, col, th); });
    });
  });
  document.querySelectorAll("fieldset.filters input").forEach(function (i) { i.addEventListener("change", filter); });
})();
