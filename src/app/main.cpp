// capsflow command line (design.md §5): thin — parse, build, run.
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <exception>

#include "capsflow/core/version.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App cli{"capsflow — an elastic capsule (MITC3 GSMB shell) freely suspended in Stokes flow"};
  cli.require_subcommand(0, 1);
  bool show_version = false;
  cli.add_flag("--version", show_version, "print version, git hash and dependency versions");

  capsflow::app::InfoOptions info;
  CLI::App* info_cmd = cli.add_subcommand("info", "print the resolved scene and a report of its mesh");
  info_cmd->add_option("scene", info.scene_path, "scene file (TOML); default: the built-in default scene");
  info_cmd->add_option("--set", info.overrides, "override a scene key, e.g. --set mesh.level=5");

  CLI11_PARSE(cli, argc, argv);
  try {
    if (show_version) {
      const auto b = capsflow::build_info();
      fmt::print("capsflow {} (git {})\n{}\n", b["version"].get<std::string>(), b["git"].get<std::string>(), b.dump(2));
      return 0;
    }
    if (*info_cmd) return capsflow::app::info_command(info);
    // Until the coupled solver lands, the main job reports the default scene.
    return capsflow::app::info_command({});
  } catch (const std::exception& e) {
    fmt::print(stderr, "capsflow: error: {}\n", e.what());
    return 1;
  }
}
