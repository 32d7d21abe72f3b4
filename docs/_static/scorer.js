// The site's search ranking: functions, classes and pages first; a class's
// attributes (dataclass fields) after them, so searching "minimax" shows fit,
// fpminimax and minimax_powers before the fields of a class named FpminimaxCase.
var Scorer = {
  score: result => {
    const [docname, title, anchor, descr, score, filename, kind] = result;
    if (descr && /^Python (attribute|property)\b/.test(descr)) {
      return score - 15;
    }
    return score;
  },
  objNameMatch: 11,
  objPartialMatch: 6,
  objPrio: {0: 15, 1: 5, 2: -5},
  objPrioDefault: 0,
  title: 15,
  partialTitle: 7,
  term: 5,
  partialTerm: 2,
};
