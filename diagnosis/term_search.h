// Stage 5c of the torque fit (diagnose.h): the search for terms beyond the table (DESIGN.md "Terms
// beyond the table"), run on what the table's best model leaves.
//
// Method:
//  - the target is the residual of the model without the table's effects, r0 = r + sum_k v_k C_k,
//    with C_k = (tau_S(extended) - tau_S(extended without effect k)) / v_k each named effect's exact
//    contribution per unit value (its secant: exact for the families linear in their value), so
//    that the table's effects are refitted beside a term and can be dropped;
//  - candidates: term_library.h's grammar at every joint with data; a term's column is
//    dtau_S / d(value) = -expr (a link term), filtered as the residual (parallel filtering);
//  - screening: every candidate's drop of the train rows' error after projecting out the current
//    model (a strided subset of the fit rows, unfiltered), inner parameters on their grids then
//    refined by golden search; the best kScreened go to the exact fit;
//  - the exact fit and the gates are the table's (diagnose_select.h FitCols, the records' effective
//    sample size): the BIC drops by more than kBicMargin + ln(candidates screened) (the extended
//    BIC's price of a search over many models, Chen & Chen 2008, Biometrika 95:759, gamma = 1/2),
//    the held-out error at the term's joint drops by kMinHeldoutGain of its value and by the
//    materiality floor, with several records also every record left out in turn, and the term is
//    significant (|t| > kMinT); among admissible terms, one of lower complexity within kParsimony of
//    the best's held-out gain wins;
//  - after each term, a table effect that no longer earns the BIC margin or |t| > kMinT is dropped
//    (backward elimination): no false cause stays beside the term that explains its share.
// Nothing changes where no term is admitted.
#pragma once
#include <string>
#include <vector>

#include "diagnosis/diagnose_internal.h"
#include "diagnosis/diagnose_select.h"

namespace exotwin {
namespace torque_fit {

constexpr int kMaxTerms = 3;     // terms named at most (all joints)
constexpr size_t kScreened = 12;  // candidates per step fitted exactly

struct TermSearchResult {
  bool changed = false;                          // a term was admitted (D's effects were rewritten)
  std::vector<std::vector<Effect>> left_out;     // per record: the final effects fitted without it
};

// Runs the search at the joints `at_joint` (those whose table model is incomplete, completeness.h)
// on the records' fit rows (banks[r].sample, .train; their X may be released),
// with D->effects and D->extended the table's best model (stage 5). Where a term is admitted,
// rewrites D->effects (the kept table effects refitted, the terms) and D->extended, and appends its
// steps in words to D->term_search. The screening on up to `threads` threads (the same result on any
// count).
TermSearchResult SearchTerms(const LegParams& params, const std::vector<Rec>& recs, const double w[2],
                             const std::vector<ColumnBank>& banks, const PhysicalScale& scale,
                             const bool at_joint[2], int threads, Diagnosis* D);

}  // namespace torque_fit
}  // namespace exotwin
