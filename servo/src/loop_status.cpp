// The loop's words (to_string) and its mode machine's transition table.
#include "ofv/servo/loop_status.h"

namespace ofv::servo {

const char* to_string(StepStatus status) {
  switch (status) {
    case StepStatus::Converged: return "converged";
    case StepStatus::NotConverged: return "not_converged";
    case StepStatus::NoOccluders: return "no_occluders";
    case StepStatus::ObjectLost: return "object_lost";
    case StepStatus::BadFrame: return "bad_frame";
    case StepStatus::Planned: return "planned";
  }
  return "?";
}

const char* to_string(LoopMode mode) {
  switch (mode) {
    case LoopMode::Pursue: return "pursue";
    case LoopMode::Hold: return "hold";
    case LoopMode::WayBack: return "way_back";
    case LoopMode::Waiting: return "waiting";
    case LoopMode::Lost: return "lost";
  }
  return "?";
}

const char* to_string(Guard guard) {
  switch (guard) {
    case Guard::None: return "none";
    case Guard::T0Clear: return "t0_clear";
    case Guard::SceneChanged: return "scene_changed";
    case Guard::ObjectLost: return "object_lost";
    case Guard::ObjectLostNoView: return "object_lost_no_view";
    case Guard::BackThere: return "back_there";
    case Guard::AwayAgain: return "away_again";
    case Guard::ObjectFound: return "object_found";
  }
  return "?";
}

const char* to_string(Proposer proposer) {
  switch (proposer) {
    case Proposer::None: return "none";
    case Proposer::Estimate: return "estimate";
    case Proposer::Anticipated: return "anticipated";
    case Proposer::WarmStart: return "warm_start";
    case Proposer::Climb: return "climb";
    case Proposer::Here: return "here";
    case Proposer::BestSeen: return "best_seen";
    case Proposer::InitialView: return "initial_view";
    case Proposer::Sampling: return "sampling";
    case Proposer::Plan: return "plan";
  }
  return "?";
}
const std::vector<LoopTransition>& loop_transitions() {
  static const std::vector<LoopTransition> table{
      {LoopMode::Pursue, Guard::ObjectLost, LoopMode::WayBack},
      {LoopMode::Pursue, Guard::ObjectLostNoView, LoopMode::Lost},
      {LoopMode::Hold, Guard::T0Clear, LoopMode::Pursue},
      {LoopMode::Hold, Guard::SceneChanged, LoopMode::Pursue},
      {LoopMode::Hold, Guard::ObjectLost, LoopMode::WayBack},
      {LoopMode::WayBack, Guard::BackThere, LoopMode::Waiting},
      {LoopMode::WayBack, Guard::ObjectFound, LoopMode::Hold},
      {LoopMode::Waiting, Guard::AwayAgain, LoopMode::WayBack},
      {LoopMode::Waiting, Guard::ObjectFound, LoopMode::Hold},
      {LoopMode::Lost, Guard::ObjectFound, LoopMode::Pursue},
  };
  return table;
}

}  // namespace ofv::servo
