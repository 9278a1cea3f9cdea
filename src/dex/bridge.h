#pragma once
// What crosses drone boundaries (paper, section V): when an internal node ends, the
// OutBridge tells every drone holding a node it links to; the InBridge of that drone
// applies the links of its external copy of the node. A Do condition's flip is broadcast
// so every drone cancels its part of the do-branch.
#include <string>

#include "graph/meg.h"

namespace eamos::dex {

struct Message {
  enum class Kind {
    ended,   ///< node `meg` held by `from` ended with `branch`
    cancel,  ///< Do condition `meg` held by `from` flipped: cancel its do-branch
  };
  Kind kind = Kind::ended;
  std::string mission_hash;  ///< receivers ignore messages of another mission
  int from = 0;              ///< sending drone
  int meg = 0;               ///< MEG id of the node that ended / flipped
  graph::Branch branch = graph::Branch::any;
};

/// The transport under InBridge and OutBridge: in-process here; DDS between processes.
class Transport {
 public:
  virtual ~Transport() = default;
  /// Delivers `m` to drone `to` later (never inside send), in send order per sender.
  virtual void send(int to, const Message& m) = 0;
};

}  // namespace eamos::dex
