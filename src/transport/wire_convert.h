#pragma once
// Between the C++ samples (samples.h) and the C structs idlc generates from wire.idl.
// Writing borrows the C++ strings (dds_write serialises before it returns); reading
// copies out of the loaned sample.
#include <string>
#include <vector>

#include "transport/samples.h"
#include "wire.h"

namespace eamos::transport {

/// A C struct for dds_write that points into `keep`, which must outlive the write.
struct TelemetryOut {
  eamos_wire_Telemetry c{};
  std::vector<eamos_wire_SensorValue> sensors;
};

eamos_wire_Trigger to_wire(const TriggerSample& s);
void to_wire(const TelemetrySample& s, TelemetryOut& out);
eamos_wire_Lifecycle to_wire(const LifecycleSample& s);
eamos_wire_Status to_wire(const StatusSample& s);
eamos_wire_TraceRecord to_wire(const TraceSample& s);

TriggerSample from_wire(const eamos_wire_Trigger& w);
TelemetrySample from_wire(const eamos_wire_Telemetry& w);
LifecycleSample from_wire(const eamos_wire_Lifecycle& w);
StatusSample from_wire(const eamos_wire_Status& w);
TraceSample from_wire(const eamos_wire_TraceRecord& w);

}  // namespace eamos::transport
