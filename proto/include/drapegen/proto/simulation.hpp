#pragma once
// The wire form of a drape to compute elsewhere (v1::Simulation) and of its outcome (v1::SimulatedDrape): a
// sim::DrapeConfig and the parts of a sim::DrapeResult the gap diagnosis reads, carried value for value, so that a
// worker computes the very drape its sender would have (docs/DIAGNOSIS.md, "Refits on workers").

#include "drapegen/proto/codec.hpp"
#include "drapegen/sim/drape.hpp"

namespace drapegen::proto {

/// Errors where the config has what the wire form does not carry: a mesh initial state, or solver options other than
/// DrapeConfig's defaults beyond max_iterations and tolerance.
[[nodiscard]] sim::Expected<v1::Simulation> to_proto(const sim::DrapeConfig& config);
/// Errors on an enum value out of range, a non-finite or non-positive size, or a vertex count outside 2..1000 (the
/// simulator validates the rest when it builds the drape).
[[nodiscard]] sim::Expected<sim::DrapeConfig> from_proto(const v1::Simulation& simulation);

[[nodiscard]] v1::SimulatedDrape to_proto(const sim::DrapeResult& result);
/// The mesh, the solve's outcome, iterations, residual, energy and message, and the rest angles (the rest of the
/// result is left at its defaults). Errors where the arrays do not make a mesh (sizes, vertex indices).
[[nodiscard]] sim::Expected<sim::DrapeResult> from_proto(const v1::SimulatedDrape& drape);

}  // namespace drapegen::proto
