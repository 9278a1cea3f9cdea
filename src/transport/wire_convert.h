#pragma once
// Between the C++ samples (samples.h) and the C structs idlc generates from wire.idl.
// Writing borrows the C++ strings (dds_write serialises before it returns); reading
// copies out of the loaned sample, and checks it first: a sample comes from anyone on the
// domain, so every field is checked against the rules of docs/faults.md ("What arrives
// over DDS") and a sample that breaks one is refused, never converted.
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

/// Converts a received sample into `out`; false with `why` (which field, what is wrong)
/// when a field breaks its rule: a drone index outside the fleet, an unknown enum value,
/// NaN or an infinity, a negative count, a string too long or not UTF-8. The caller
/// drops such a sample and logs `why`.
bool from_wire(const eamos_wire_Trigger& w, const WireLimits& limits, TriggerSample& out, std::string& why);
bool from_wire(const eamos_wire_Telemetry& w, const WireLimits& limits, TelemetrySample& out, std::string& why);
bool from_wire(const eamos_wire_Lifecycle& w, const WireLimits& limits, LifecycleSample& out, std::string& why);
bool from_wire(const eamos_wire_Status& w, const WireLimits& limits, StatusSample& out, std::string& why);
bool from_wire(const eamos_wire_TraceRecord& w, const WireLimits& limits, TraceSample& out, std::string& why);

}  // namespace eamos::transport
