// What plans the tip's way to a goal for `sim --input goal` (docs/mhsb.md, "The K70M: a goal for
// sim"): the product's one view of the point-to-point planner, which is research's
// (research/planner; the craneassist executable builds it, app/cli/research/goal_move.hpp). It
// plans on a thread of its own and hands each plan to the GoalSource as a tip trajectory, never
// on the control thread; the goal may change while the tip moves.
#pragma once

#include <string>
#include <vector>

#include "craneassist/input/goal_source.hpp"

namespace craneassist::input {

class GoalPlanning {
 public:
  virtual ~GoalPlanning() = default;
  // Starts planning the goals for source, which must outlive stop().
  virtual void start(GoalSource& source) = 0;
  // Stops planning and joins the thread; safe to call twice.
  virtual void stop() = 0;
  // Lines for the run's summary: goals planned, planning times, goals refused and why.
  virtual std::vector<std::string> report() const = 0;
};

}  // namespace craneassist::input
