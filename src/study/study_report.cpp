#include "capsflow/core/study/study_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/io/version.hpp"

namespace capsflow::study {

namespace {

nlohmann::json opt(const std::optional<double>& v) {
  return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json(nullptr);
}
nlohmann::json finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json row_json(const ConvergenceRow& row) {
  const ConvergenceEstimate& e = row.estimate;
  nlohmann::json values = nlohmann::json::array(), errors = nlohmann::json::array();
  for (double v : row.values) values.push_back(finite(v));
  for (const auto& err : e.errors) errors.push_back(opt(err));
  nlohmann::json j = {{"family", family_label(row.family)}, {"observable", row.observable}, {"t", row.t},
                      {"levels", row.levels}, {"values", values}, {"status", to_string(e.status)},
                      {"order", opt(e.order)}, {"extrapolated", opt(e.extrapolated)}, {"uncertainty", opt(e.uncertainty)},
                      {"errors", errors}};
  if (e.previous)
    j["previous_triple"] = {{"status", to_string(e.previous->status)}, {"order", opt(e.previous->order)},
                            {"extrapolated", opt(e.previous->extrapolated)}};
  std::string note = e.note;
  if (!row.note.empty()) note += (note.empty() ? "" : "; ") + row.note;
  if (!note.empty()) j["note"] = note;
  return j;
}

// Shortest round-trip form; empty for a missing value.
std::string num(const std::optional<double>& v) { return v && std::isfinite(*v) ? fmt::format("{}", *v) : std::string(); }

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string sig(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : std::string("–"); }
std::string sci(const std::optional<double>& v) { return v && std::isfinite(*v) ? fmt::format("{:.2e}", *v) : std::string("–"); }

}  // namespace

const std::vector<std::string>& study_manifest() {
  static const std::vector<std::string> names = {kStudyJson, kStudyCsv, kStudyMarkdown};
  return names;
}

nlohmann::json study_json(const StudyReport& r) {
  const StudyPlan& p = r.plan;
  nlohmann::json vary = nlohmann::json::array();
  for (const VaryAxis& a : p.vary) vary.push_back({{"key", a.key}, {"values", a.values}});
  nlohmann::json families = nlohmann::json::array();
  for (const std::string& f : p.families) families.push_back(family_label(f));
  nlohmann::json j;
  j["study"] = {{"scene", p.scene_path.empty() ? std::string(kBuiltInSceneName) : p.scene_path},
                {"set", p.overrides}, {"levels", p.levels}, {"vary", vary}, {"families", families},
                {"command_line", r.command_line}, {"version", version_string()}, {"git", git_hash()},
                {"refinement", "h halves from one level to the next"},
                {"sane_order_range", {kMinSaneOrder, kMaxSaneOrder}}, {"base_scene", base_scene_json(p)},
                {"scene_text", p.variants.front().scene.toml_text}};
  nlohmann::json variants = nlohmann::json::array();
  for (std::size_t i = 0; i < p.variants.size(); ++i) {
    const Variant& v = p.variants[i];
    const VariantRecord& rec = r.records[i];
    nlohmann::json jv = {{"name", v.name}, {"family", family_label(v.family)}, {"level", v.level},
                         {"elements", v.elements}, {"state", to_string(rec.state)}};
    if (!rec.note.empty()) jv["note"] = rec.note;
    if (rec.result) {
      const VariantResult& res = *rec.result;
      nlohmann::json phases = nlohmann::json::object(), final_values = nlohmann::json::object();
      for (const auto& [k, s] : res.seconds_per_evaluation_by_phase) phases[k] = finite(s);
      for (const auto& [k, s] : res.final_values) final_values[k] = finite(s);
      jv.update({{"stop_reason", res.stop.to_string()}, {"t", res.t_final}, {"nodes", res.nodes},
                 {"wall_seconds", finite(res.wall_seconds)}, {"rhs_evaluations", res.rhs_evaluations},
                 {"seconds_per_evaluation", finite(res.seconds_per_evaluation)},
                 {"seconds_per_evaluation_by_phase", phases}, {"peak_rss_mb", finite(res.peak_rss_mb)},
                 {"final", final_values}});
      if (res.summary.contains("far_field_check")) jv["far_field_check"] = res.summary["far_field_check"];
    }
    variants.push_back(jv);
  }
  j["variants"] = variants;
  j["notes"] = r.analysis.notes;
  nlohmann::json fin = nlohmann::json::array(), series = nlohmann::json::array();
  for (const ConvergenceRow& row : r.analysis.final_rows) fin.push_back(row_json(row));
  for (const ConvergenceRow& row : r.analysis.time_rows) series.push_back(row_json(row));
  j["final"] = fin;
  j["series"] = series;
  return j;
}

std::string study_csv(const StudyReport& r) {
  const std::vector<int>& levels = r.plan.levels;
  std::string out = "family,observable,time,status,order,extrapolated,uncertainty";
  for (int l : levels) out += fmt::format(",value_L{}", l);
  for (int l : levels) out += fmt::format(",error_L{}", l);
  out += ",note\n";
  auto add = [&](const ConvergenceRow& row) {
    const ConvergenceEstimate& e = row.estimate;
    out += csv_field(family_label(row.family)) + "," + row.observable + "," + (row.final ? std::string("final") : num(row.t)) +
           "," + to_string(e.status) + "," + num(e.order) + "," + num(e.extrapolated) + "," + num(e.uncertainty);
    for (int pass = 0; pass < 2; ++pass)
      for (int l : levels) {
        std::optional<double> v;
        for (std::size_t i = 0; i < row.levels.size(); ++i)
          if (row.levels[i] == l) v = pass == 0 ? std::optional<double>(row.values[i]) : e.errors[i];
        out += "," + num(v);
      }
    std::string note = e.note;
    if (!row.note.empty()) note += (note.empty() ? "" : "; ") + row.note;
    out += "," + csv_field(note) + "\n";
  };
  for (const ConvergenceRow& row : r.analysis.final_rows) add(row);
  for (const ConvergenceRow& row : r.analysis.time_rows) add(row);
  return out;
}

std::string study_markdown(const StudyReport& r) {
  const StudyPlan& p = r.plan;
  std::string md = "# Convergence study\n\n";
  if (!r.command_line.empty()) md += "    " + r.command_line + "\n\n";
  std::string fams;
  for (const std::string& f : p.families) fams += (fams.empty() ? "" : ", ") + family_label(f);
  md += fmt::format("Scene `{}`, levels {}–{} (h halves per level), families: {}. capsflow {} (git {}).\n\n",
                    p.scene_path.empty() ? kBuiltInSceneName : p.scene_path, p.levels.front(), p.levels.back(), fams,
                    version_string(), git_hash());
  md += fmt::format(
      "p: observed order log2(e1/e2) of the three finest levels (e1, e2 their two differences); f*: Richardson "
      "extrapolation; ±: spread of the extrapolations of the last two level triples (four or more levels). "
      "Status other than `asymptotic` (differences of one sign, p in [{:g}, {:g}]): no order is claimed.\n\n",
      kMinSaneOrder, kMaxSaneOrder);

  // Cost per variant: phases as milliseconds per evaluation.
  // Phases no variant spent time in (bie_verify without fluid.verify_every) are left out.
  std::vector<std::string> phases;
  for (const VariantRecord& rec : r.records)
    if (rec.result)
      for (const auto& [k, s] : rec.result->seconds_per_evaluation_by_phase)
        if (s > 0 && std::find(phases.begin(), phases.end(), k) == phases.end()) phases.push_back(k);
  md += "## Variants\n\n| variant | elements | state | t | wall s | evaluations | ms/eval |";
  for (const std::string& ph : phases) md += " " + ph + " |";
  md += " peak MB |\n|---|---:|---|---:|---:|---:|---:|";
  for (std::size_t i = 0; i < phases.size(); ++i) md += "---:|";
  md += "---:|\n";
  for (std::size_t i = 0; i < p.variants.size(); ++i) {
    const Variant& v = p.variants[i];
    const VariantRecord& rec = r.records[i];
    if (!rec.result) {
      md += fmt::format("| {} | {} | {} |  |  |  |  |", v.name, v.elements, to_string(rec.state));
      for (std::size_t k = 0; k < phases.size(); ++k) md += "  |";
      md += "  |\n";
      continue;
    }
    const VariantResult& res = *rec.result;
    md += fmt::format("| {} | {} | {} | {:g} | {:.1f} | {} | {:.2f} |", v.name, res.elements,
                      rec.state == VariantState::Finished ? std::string(to_string(rec.state)) : to_string(rec.state) + (" (" + res.stop.to_string() + ")"), res.t_final,
                      res.wall_seconds, res.rhs_evaluations, 1e3 * res.seconds_per_evaluation);
    for (const std::string& ph : phases) {
      const auto it = res.seconds_per_evaluation_by_phase.find(ph);
      md += it == res.seconds_per_evaluation_by_phase.end() ? "  |" : fmt::format(" {:.2f} |", 1e3 * it->second);
    }
    md += fmt::format(" {:.0f} |\n", res.peak_rss_mb);
  }
  md += "\nPhases in ms per evaluation (the last run segment). Peak memory is the process's high-water mark at the end "
        "of the variant: run one after the other in one process, it bounds the variant's own peak from above; with --jobs or Slurm each variant has its own process.\n";

  // Final values per family.
  const std::string* current = nullptr;
  for (const ConvergenceRow& row : r.analysis.final_rows) {
    if (!current || row.family != *current) {
      current = &row.family;
      md += fmt::format("\n## {} at the end (γ̇t = {:g})\n\n| observable |", family_label(row.family), row.t);
      for (int l : row.levels) md += fmt::format(" L{} |", l);
      md += " p | f* | ± | \\|f_finest − f*\\| | status |\n|---|";
      for (std::size_t i = 0; i < row.levels.size(); ++i) md += "---:|";
      md += "---:|---:|---:|---:|---|\n";
    }
    const ConvergenceEstimate& e = row.estimate;
    md += "| " + row.observable + " |";
    for (double v : row.values) md += " " + sig(v) + " |";
    md += fmt::format(" {} | {} | {} | {} | {}{} |\n", e.order ? fmt::format("{:.2f}", *e.order) : "–",
                      e.extrapolated ? sig(*e.extrapolated) : "–", sci(e.uncertainty),
                      e.errors.empty() ? std::string("–") : sci(e.errors.back() ? std::optional<double>(std::abs(*e.errors.back())) : std::nullopt),
                      to_string(e.status), row.note.empty() ? "" : " (" + row.note + ")");
  }
  if (!r.analysis.notes.empty()) {
    md += "\n## Notes\n\n";
    for (const std::string& n : r.analysis.notes) md += "- " + n + "\n";
  }
  md += "\nEvery output time: study.csv and study.json (`series`).\n";
  return md;
}

void write_study_reports(const std::filesystem::path& dir, const StudyReport& r) {
  io::write_file_atomically(dir / kStudyJson, study_json(r).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  io::write_file_atomically(dir / kStudyCsv, study_csv(r));
  io::write_file_atomically(dir / kStudyMarkdown, study_markdown(r));
}

}  // namespace capsflow::study
