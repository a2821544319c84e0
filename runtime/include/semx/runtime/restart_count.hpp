// How often the launcher has restarted this process: SEMX_RESTART in its environment, set by
// semx-launch to 0 at the first start and n at the n-th restart (docs/launch.md). A node reports
// it in NODE_STATUS; a process with saved state resumes from it when the count is above 0 and
// starts afresh (overwriting any stale state) at 0.
#pragma once

namespace semx::runtime {

inline constexpr const char* kRestartEnv = "SEMX_RESTART";

// 0 when the variable is absent or not a non-negative integer.
int restart_count();

}  // namespace semx::runtime
