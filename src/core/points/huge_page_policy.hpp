// Whether this machine's transparent huge pages are worth asking for.
//
// On bare metal a huge page is the cheap case: one fault and one TLB entry per 2 MiB. Under a
// hypervisor with free page reporting (virtio-balloon; e.g. Firecracker) the guest hands every
// free block of 2 MiB or more back to the host, which drops its memory, and then either size
// can be the dear one:
// - On one host every huge-page fault became a host fault that rebuilt 2 MiB from nothing,
//   while small pages came from the guest's fragmented, unreported free memory (24.2 M LAS
//   points, build --save: 4.1 s with huge pages against 1.95 s with small ones after the
//   machine had been idle).
// - On another, whose hypervisor shadows the guest's page tables, each small page's first touch
//   cost 13-16 us (6-8 ms a 2 MiB) against 0.15-4 ms for a huge page, and the same build took
//   1.6 s with huge pages against 2.0 s with small ones.
// So where reporting is active the choice is measured: a few MiB touched each way, once per
// process.
#pragma once

#include <functional>
#include <optional>
#include <string>

namespace omicron {

// True unless free page reporting is active and small pages measure cheaper there (see above);
// the environment variable OMICRON_HUGE_PAGES (0 or 1) overrides. Decided once per process.
bool hugePagesPayOff();

// Seconds a MiB of fresh anonymous memory takes to fault in, written once per small page, on
// huge pages and on small ones (huge: infinite where transparent huge pages are off).
struct FirstTouchCost {
    double hugeSecondsPerMiB = 0.0;
    double smallSecondsPerMiB = 0.0;
};
// Maps 4 MiB on huge pages and 2 MiB on small ones, touches them and unmaps them: about 6 ms
// where small pages are dear.
FirstTouchCost measureFirstTouchCost();

// The decision itself, for tests: `override` is OMICRON_HUGE_PAGES's value (if set),
// `pageReportingParameters` the kernel's page_reporting module parameters folder, whose
// reported_kib counts the memory handed back to the host (absent or 0: no reporting), and
// `measure` is called only where reporting is active.
bool hugePagesPayOff(const std::optional<std::string>& override,
                     const std::string& pageReportingParameters,
                     const std::function<FirstTouchCost()>& measure);

} // namespace omicron
