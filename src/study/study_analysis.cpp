#include "capsflow/core/study/study_analysis.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace capsflow::study {

namespace {

// Every observable is O(1) or a small difference of O(1) numbers in capsflow's units (D_ij, lengths
// in ℓ, area in ℓ², volume drift V/V0 − 1): its round-off is relative to 1 at least.
constexpr double kObservableScale = 1.0;

// Output times of the same scene agree to rounding across levels (they are k·every).
bool same_time(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(a)); }

std::optional<std::size_t> find_time(const std::vector<double>& times, double t) {
  for (std::size_t i = 0; i < times.size(); ++i)
    if (same_time(times[i], t)) return i;
  return std::nullopt;
}

}  // namespace

StudyAnalysis analyse_study(const StudyPlan& plan, const std::vector<VariantRecord>& records) {
  StudyAnalysis a;
  for (const std::string& family : plan.families) {
    const std::string label = family_label(family);
    // Finished results of this family by level.
    std::vector<std::pair<int, const VariantResult*>> done;
    std::vector<std::string> missing;
    for (std::size_t i = 0; i < plan.variants.size(); ++i) {
      const Variant& v = plan.variants[i];
      if (v.family != family) continue;
      if (records[i].state == VariantState::Finished && records[i].result) done.emplace_back(v.level, &*records[i].result);
      else missing.push_back(fmt::format("L{} {}", v.level, to_string(records[i].state)));
    }
    if (done.empty()) {
      a.notes.push_back(label + ": no finished level yet");
      continue;
    }
    // The longest run of consecutive finished levels ending at the finest finished one.
    std::size_t first = done.size() - 1;
    while (first > 0 && done[first - 1].first == done[first].first - 1) --first;
    if (!missing.empty() || first > 0) {
      std::string left_out;
      for (std::size_t i = 0; i < first; ++i) left_out += fmt::format("{}L{}", left_out.empty() ? "" : ", ", done[i].first);
      std::string m;
      for (const std::string& s : missing) m += (m.empty() ? "" : ", ") + s;
      a.notes.push_back(fmt::format("{}: analysed levels {}–{}{}{}", label, done[first].first, done.back().first,
                                    m.empty() ? "" : "; not finished: " + m,
                                    left_out.empty() ? "" : "; left out (not consecutive with the finest): " + left_out));
    }
    std::vector<int> levels;
    std::vector<const VariantResult*> results;
    for (std::size_t i = first; i < done.size(); ++i) {
      levels.push_back(done[i].first);
      results.push_back(done[i].second);
    }

    // The observables every level has: a channel's too when all are channel runs.
    std::vector<std::string> observables = observable_names();
    bool channel = true;
    for (const VariantResult* r : results) channel = channel && r->series.count(channel_observable_names().front()) > 0;
    if (channel) observables.insert(observables.end(), channel_observable_names().begin(), channel_observable_names().end());

    // At the end of the run.
    double t_min = results.front()->t_final, t_max = t_min;
    for (const VariantResult* r : results) t_min = std::min(t_min, r->t_final), t_max = std::max(t_max, r->t_final);
    for (const std::string& obs : observables) {
      ConvergenceRow row;
      row.family = family;
      row.observable = obs;
      row.final = true;
      row.t = results.back()->t_final;
      row.levels = levels;
      for (const VariantResult* r : results) row.values.push_back(r->final_values.at(obs));
      row.estimate = estimate_convergence(row.values, kObservableScale);
      if (!same_time(t_min, t_max))
        row.note = fmt::format("final times differ between levels ({:g} to {:g}: a steady-state stop)", t_min, t_max);
      a.final_rows.push_back(std::move(row));
    }

    // At every output time all levels share (the finest level's times, found in every other).
    const VariantResult& finest = *results.back();
    for (std::size_t k = 0; k < finest.times.size(); ++k) {
      const double t = finest.times[k];
      std::vector<std::size_t> index;
      for (const VariantResult* r : results) {
        const auto j = find_time(r->times, t);
        if (!j) break;
        index.push_back(*j);
      }
      if (index.size() != results.size()) continue;
      for (const std::string& obs : observables) {
        ConvergenceRow row;
        row.family = family;
        row.observable = obs;
        row.t = t;
        row.levels = levels;
        for (std::size_t i = 0; i < results.size(); ++i) row.values.push_back(results[i]->series.at(obs)[index[i]]);
        row.estimate = estimate_convergence(row.values, kObservableScale);
        a.time_rows.push_back(std::move(row));
      }
    }
  }
  return a;
}

}  // namespace capsflow::study
