#include "cli/output_flags.h"

namespace bouncefit::cli {

CLI::Option* AddOutputFlags(CLI::App* cmd, std::string* out, bool* overwrite, const std::string& files) {
  const std::string group = "Output";
  auto* option = cmd->add_option("--out", *out, "write " + files + " into this directory (docs/FORMATS.md)")->group(group);
  cmd->add_flag("--overwrite", *overwrite, "--out holds an earlier run's files: clear the ones this writes first")
      ->group(group);
  return option;
}

}  // namespace bouncefit::cli
