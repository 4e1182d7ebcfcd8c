#include "pipeline/pipeline.h"

#include <fmt/format.h>

#include "msgs/lcm_bus.h"
#include "pipeline/output_dir.h"

namespace bouncefit {

Pipeline::Pipeline(PipelineConfig config, NoticeFn notice) : config_(std::move(config)), notice_(std::move(notice)) {
  if (!notice_) notice_ = [](const std::string&) {};
  const bool existed = std::filesystem::exists(config_.out_dir);
  ClaimOutputDir(config_.out_dir, RunOutputFiles(), config_.overwrite);
  try {
    Open();
  } catch (...) {
    // A source or a flag refused before the stream began: leave no trace of this run.
    RemoveOutputFiles(config_.out_dir, RunOutputFiles());
    std::error_code ec;
    if (!existed) std::filesystem::remove(config_.out_dir, ec);  // only if empty
    throw;
  }
}

void Pipeline::Open() {
  config_.capture.out_dir = config_.detect.out_dir = config_.out_dir;
  config_.detect.announce_stream = false;  // run says it in its first line
  if (config_.fit) config_.fit->out_dir = config_.out_dir;
  bus_ = std::make_unique<LcmBus>("memq://");
  if (!config_.lcm_url.empty() && config_.lcm_url.rfind("memq://", 0) != 0) {
    outside_ = std::make_unique<LcmBus>(config_.lcm_url);
    bus_->set_mirror(outside_.get());
  }
  // Downstream first: each node listens before anything it hears is sent.
  if (config_.fit) fit_ = std::make_unique<FitStage>(*config_.fit, *bus_, notice_);
  detect_ = std::make_unique<DetectStage>(config_.detect, *bus_, notice_);
  capture_ = std::make_unique<CaptureStage>(config_.capture, *bus_, notice_);
}

Pipeline::~Pipeline() = default;

PipelineOutcome Pipeline::Run(const std::atomic<bool>* stop, const std::function<void()>& progress,
                              const std::function<void(int, int)>& fit_progress) {
  const auto check_flags = [&] {
    if (detect_->fatal().empty()) return;
    const std::string why = detect_->fatal();
    capture_->End(true);
    if (fit_) fit_->Stop();
    RemoveOutputFiles(config_.out_dir, RunOutputFiles());  // nothing of a run on a scale it contradicts
    throw std::invalid_argument(why);
  };
  while (!(stop && *stop) && capture_->Step()) {
    bus_->Drain();
    if (fit_) fit_->Poll();
    check_flags();
    if (progress) progress();
  }
  const bool stopped = stop && *stop;
  capture_->End(stopped);
  bus_->Drain();
  check_flags();
  if (!detect_->done()) detect_->FinishWithoutEnd();
  bus_->Drain();
  PipelineOutcome out;
  out.stream = capture_->end_message();
  out.rows = detect_->rows();
  out.rebounds = detect_->rebounds();
  if (fit_) {
    if (stopped) {
      fit_->Stop();
      fit_->Poll();
    } else {
      fit_->WaitDone([&](int sims, int budget) {
        bus_->Drain();  // the updates the fit published reach whoever follows the session
        if (fit_progress) fit_progress(sims, budget);
      });
      bus_->Drain();
    }
    out.final_fit = fit_->final_fit();
  }
  const stream_t& s = out.stream;
  const std::string input = s.input;
  if (stopped) {
    out.status = kExitInterrupted;
    out.why = "stopped";
  } else if (!s.failure.empty() && out.rows == 0) {
    out.status = kExitError;
    out.why = s.failure + "; nothing usable was read";
  } else if (s.ended_short && out.rows == 0) {
    out.status = kExitError;
    out.why = fmt::format("{} ended after {} of the {} frames it announces (truncated or damaged?); nothing usable was read",
                          input, s.frames, s.announced_frames);
  } else if (s.frames > 0 && s.found == 0) {
    out.status = kExitNoBounce;
    out.why = fmt::format("{}: no ball found in any of its {} frames{}", input, s.frames,
                          s.tracker_named ? " (nothing of the colour or brightness given)"
                                          : " (nothing moved like a ball and stood out of its surroundings; if it "
                                            "is there, --color or --pick names it)");
  } else if (out.rebounds == 0) {
    out.status = kExitNoBounce;
    out.why = fmt::format("{}: no bounce found (the ball, or what was taken for it, was seen in {} of {} frames, never "
                          "on an arc between two impacts above the floor; --color or --pick names the ball)",
                          input, s.found, s.frames);
  } else if (!s.failure.empty()) {
    out.status = kExitError;
    out.why = s.failure;
  } else if (fit_ && !out.final_fit) {
    out.status = kExitNoFit;
    out.why = !fit_->no_fit_why().empty()
                  ? "no fit: " + fit_->no_fit_why()
                  : "no fit: the bounces found gave none (two apexes in a row of 1 cm or more are needed: a start and a "
                    "rebound after it)";
  }
  return out;
}

}  // namespace bouncefit
