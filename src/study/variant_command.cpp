#include "capsflow/core/study/variant_command.hpp"

#include <filesystem>

namespace capsflow::study {
namespace fs = std::filesystem;

std::vector<std::string> variant_command(const std::string& exe, const StudyOptions& o, const std::string& variant, int threads) {
  std::vector<std::string> argv = {exe, "study"};
  if (!o.scene_path.empty()) argv.push_back(fs::absolute(o.scene_path).lexically_normal().string());
  std::string levels;
  for (int l : o.levels) levels += (levels.empty() ? "" : ",") + std::to_string(l);
  argv.insert(argv.end(), {"--levels", levels});
  for (const std::string& s : o.overrides) argv.insert(argv.end(), {"--set", s});
  for (const VaryAxis& a : o.vary) {
    std::string values;
    for (const std::string& v : a.values) values += (values.empty() ? "" : ",") + v;
    argv.insert(argv.end(), {"--vary", a.key + "=" + values});
  }
  argv.insert(argv.end(), {"-o", fs::absolute(o.dir).lexically_normal().string()});
  if (!variant.empty()) argv.insert(argv.end(), {"--variant", variant});
  if (o.overwrite) argv.push_back("--overwrite");  // the variant itself runs anew, not only the study's files
  if (threads > 0) argv.insert(argv.end(), {"--threads", std::to_string(threads)});
  if (o.verbose) argv.push_back("--verbose");
  return argv;
}

std::string shell_quote(const std::string& w) {
  const bool safe = !w.empty() && w.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                                      "@%+=:,./-_") == std::string::npos;
  if (safe) return w;
  std::string q = "'";
  for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace capsflow::study
