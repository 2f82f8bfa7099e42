// The league and tournament pages' one script: a filter over a list of matches (words
// typed are looked for in each row's text). It reads text (textContent) and sets the rows'
// hidden flag and a count (textContent): nothing is ever parsed as markup.
(function () {
  "use strict";
  var input = document.getElementById("match-filter");
  var body = document.getElementById("match-rows");
  var count = document.getElementById("match-count");
  if (!input || !body) {
    return;
  }
  var rows = Array.prototype.slice.call(body.rows);
  var texts = rows.map(function (row) { return row.textContent.toLowerCase(); });
  function apply() {
    var words = input.value.toLowerCase().split(/\s+/).filter(Boolean);
    var shown = 0;
    rows.forEach(function (row, i) {
      var keep = words.every(function (word) { return texts[i].indexOf(word) >= 0; });
      row.hidden = !keep;
      shown += keep ? 1 : 0;
    });
    if (count) {
      count.textContent = shown + " of " + rows.length + " matches";
    }
  }
  input.hidden = false;
  input.addEventListener("input", apply);
  apply();
}());
