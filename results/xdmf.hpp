#pragma once
// XDMF (version 2: ParaView's "XDMF Reader"; its Xdmf3 readers do not take hyperslabs) descriptions of a results file for ParaView and VTK: per run, the arm at every
// step that stores the flexible state (simulation.store_flexible_every): the elastic axis of every
// link as a polyline through its start, its rfes' mass-centre stations and its free end (with the
// deflection from the undeformed axis as a point vector: ParaView's "Warp By Vector" magnifies it;
// the frame of the body each point moves with as a tensor, its columns the body's axes in {0}),
// the base as a polyline through the joint origins, payloads as points. The geometry stays in the
// HDF5 file; the XDMF selects one row of its tables per step (hyperslabs), so nothing is copied.
#include <string>
#include <vector>

namespace rfem {

/// Writes `<stem>.<run>.xdmf` next to `results` for every run (or only `runs`) that stores the
/// flexible state; returns the files written. Throws ResultsError naming the file when a run asked
/// for has no stored poses (run with simulation.store_flexible_every > 0), or when the file cannot
/// be written; nothing half-written stays behind.
std::vector<std::string> write_xdmf(const std::string& results, const std::vector<std::string>& runs = {});

}  // namespace rfem
