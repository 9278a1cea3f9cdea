#pragma once
// What `eamos verify` plugs into an in-process run, and nothing else does: it sees every
// action an engine starts, with its evaluated arguments, and it may decide which way a
// condition goes. Without an observer a run behaves exactly as before; with one it is
// still deterministic, because an observer's answers depend only on what it is told.
#include "dex/expr.h"
#include "dex/mission.h"
#include "mid/drone_api.h"

namespace eamos::dex {

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// At mission time `t`, drone `drone` is about to start action `node` with `request`;
  /// `state` is its state now.
  virtual void action_started(double t, int drone, const Node& node, const mid::ActionRequest& request,
                              const mid::DroneState& state) = 0;
  /// The value condition `node` of drone `drone` takes at `t`: `computed` is what the engine
  /// read (through `read`, which reads properties as the engine does); the answer replaces it.
  virtual bool condition(double t, int drone, const Node& node, bool computed, const PropertyReader& read) = 0;
};

}  // namespace eamos::dex
