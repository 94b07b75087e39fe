#pragma once
// How many CPUs this process may run on: the default thread count of commands that parallelise on one machine.

namespace drapegen::cli {

/// The CPUs in this process's affinity mask (what taskset, a Slurm allocation's CPU set or a container's cpuset leave
/// it), not every CPU of the machine; at least 1 (and the machine's count where the mask cannot be read).
[[nodiscard]] int usable_cpus();

}  // namespace drapegen::cli
