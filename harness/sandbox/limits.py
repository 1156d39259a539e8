"""How much memory and how many processes a student's build and node may use (pure).

Set inside the sandbox by util-linux's ``prlimit``, so the counts are the
sandbox's own: RLIMIT_AS caps each process's address space (an allocation
beyond it fails: MemoryError), RLIMIT_NPROC the processes its user runs in
the sandbox's user namespace. Linux exempts root from RLIMIT_NPROC, so a
grader run as root bounds processes only by the sandbox's lifetime (its PID
namespace dies with its run).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SandboxLimits"]

MIB = 1024 * 1024


@dataclass(frozen=True)
class SandboxLimits:
    memory_mb: int = 2048  # address space of any one process (a node with rclpy: ~1 GB)
    processes: int = 256

    def prefix(self) -> list[str]:
        """The command that starts what follows it under these limits."""
        return ["prlimit", f"--as={self.memory_mb * MIB}", f"--nproc={self.processes}", "--"]

    def describe(self) -> str:
        return f"{self.memory_mb} MB of memory per process, at most {self.processes} processes"
