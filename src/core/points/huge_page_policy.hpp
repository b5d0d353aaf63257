// Whether this machine's transparent huge pages are worth asking for.
//
// On bare metal a huge page is the cheap case: one fault and one TLB entry per 2 MiB. Under a
// hypervisor with free page reporting (virtio-balloon; e.g. Firecracker) the guest hands every
// free block of 2 MiB or more back to the host, which drops its memory. A huge page needs just
// such a block, so every huge-page fault becomes a host fault that rebuilds 2 MiB from nothing,
// while small pages come from the guest's fragmented, unreported free memory. Measured on the
// 2-core reference VM (24.2 M LAS points, build --save): 4.1 s with huge pages against 1.95 s
// with small ones after the machine had been idle, 2.5-4.0 s against 1.8-2.0 s alternating
// with PotreeConverter; only back-to-back runs that reuse the huge pages the previous run just
// freed favour them (1.4-1.8 s). So where reporting is active, arrays ask for small pages.
#pragma once

#include <optional>
#include <string>

namespace omicron {

// True unless free page reporting is active; the environment variable OMICRON_HUGE_PAGES
// (0 or 1) overrides. Decided once per process.
bool hugePagesPayOff();

// The decision itself, for tests: `override` is OMICRON_HUGE_PAGES's value (if set), and
// `pageReportingParameters` the kernel's page_reporting module parameters folder, whose
// reported_kib counts the memory handed back to the host (absent or 0: no reporting).
bool hugePagesPayOff(const std::optional<std::string>& override,
                     const std::string& pageReportingParameters);

} // namespace omicron
