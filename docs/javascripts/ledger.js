// The ledger page's filters: one select per data attribute of the rows (origin, verdict, tree,
// kind), built from the values the rows hold; a row shows when it matches every select.
(function () {
  function mount(table) {
    if (table.dataset.filtered) return;
    table.dataset.filtered = "yes";
    var rows = Array.prototype.slice.call(table.tBodies[0].rows);
    var keys = ["origin", "verdict", "tree", "kind"];
    var bar = document.createElement("div");
    bar.className = "ledger-filter";
    var count = document.createElement("span");
    var selects = {};
    keys.forEach(function (k) {
      var values = [];
      rows.forEach(function (r) {
        if (values.indexOf(r.dataset[k]) < 0) values.push(r.dataset[k]);
      });
      var label = document.createElement("label");
      label.textContent = k + " ";
      var sel = document.createElement("select");
      sel.setAttribute("aria-label", "show the claims of this " + k);
      ["all"].concat(values).forEach(function (v) {
        var o = document.createElement("option");
        o.value = v;
        o.textContent = v;
        sel.appendChild(o);
      });
      sel.addEventListener("change", apply);
      selects[k] = sel;
      label.appendChild(sel);
      bar.appendChild(label);
    });
    bar.appendChild(count);
    table.parentNode.insertBefore(bar, table);
    function apply() {
      var shown = 0;
      rows.forEach(function (r) {
        var ok = keys.every(function (k) {
          return selects[k].value === "all" || r.dataset[k] === selects[k].value;
        });
        r.style.display = ok ? "" : "none";
        shown += ok ? 1 : 0;
      });
      count.textContent = shown + " of " + rows.length + " claims shown";
    }
    apply();
  }
  function mountAll() {
    document.querySelectorAll("table.ledger").forEach(mount);
  }
  // Material's instant navigation replaces the page without a load event: follow document$
  if (typeof document$ !== "undefined") document$.subscribe(mountAll);
  else document.addEventListener("DOMContentLoaded", mountAll);
})();
