// bouncefit: the command-line entry point. Each subcommand is in cli/<name>_command.cc.
#include <cstdio>
#include <exception>

#include "capture/frame_memory.h"
#include "cli/commands.h"

int main(int argc, char** argv) {
  using namespace bouncefit::cli;
  bouncefit::KeepFreedFrameMemory();
  CLI::App app{
      "bouncefit: watch a ball bounce, measure its bounces, and fit the coefficients of a "
      "Bullet soft-body ball to them.",
      "bouncefit"};
  app.set_version_flag("--version", std::string("bouncefit ") + BOUNCEFIT_VERSION);
  app.footer(
      "Exit status: 0 an answer was written (a final fit, or the peaks with --no-fit), 1 an error, 2 a\n"
      "bad flag (or one the measurement contradicts), 3 no bounce found, 4 bounces found but no fit,\n"
      "130 stopped by Ctrl-C or SIGTERM after writing what was recorded.\n"
      "Example: bouncefit run drop.mp4 --ball tennis --out out/drop");
  app.require_subcommand(1);
  app.fallthrough(false);
  AddRunCommand(app);
  AddCaptureCommand(app);
  AddDetectCommand(app);
  AddFitCommand(app);
  AddWatchCommand(app);
  AddReportCommand(app);
  AddSynthCommand(app);
  AddSimulateCommand(app);
  AddPredictCommand(app);
  AddReplayLogCommand(app);

  // CLI11 answers --help before it looks at the words around it: `bouncefit frobnicate
  // --help` would print the main help and succeed. An unknown command is an error first.
  std::string known;
  bool is_command = false;
  const CLI::App& top = app;
  for (const auto* sub : top.get_subcommands([](const CLI::App*) { return true; })) {
    known += (known.empty() ? "" : ", ") + sub->get_name();
    is_command = is_command || (argc >= 2 && sub->get_name() == argv[1]);
  }
  if (argc >= 2 && argv[1][0] != '-' && !is_command) {
    std::fprintf(stderr, "bouncefit: error: unknown command '%s' (commands: %s; try --help)\n",
                 argv[1], known.c_str());
    return 2;
  }
  std::string command = "bouncefit";
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "bouncefit: error: %s (try --help)\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {  // a flag the command could not use
    for (const auto* sub : app.get_subcommands()) command = "bouncefit " + sub->get_name();
    std::fprintf(stderr, "%s: error: %s\n", command.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    for (const auto* sub : app.get_subcommands()) command = "bouncefit " + sub->get_name();
    std::fprintf(stderr, "%s: error: %s\n", command.c_str(), e.what());
    return 1;
  }
  return 0;
}
