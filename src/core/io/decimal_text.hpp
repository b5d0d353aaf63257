// Numbers in text point clouds (XYZ, ascii PLY): one field, the whole of it, to a double.
// std::from_chars took half of an XYZ read (26 ns a number: 3.4 M points/s on autzen_south as
// XYZ). Most fields are plain decimals such as "637172.26998" or "-1.5e-3" with at most 19
// digits, and for those whose digits fit 2^53 and whose power of ten is at most 10^22 both
// numbers are exact doubles, so one IEEE multiplication or division gives the correctly rounded
// value: the same double from_chars returns (Clinger's fast path). Everything else (more
// digits, larger exponents, "nan", "inf", hexadecimal, malformed text) goes to from_chars.
#pragma once

#include <string_view>

namespace omicron {

// True when all of `text` is a number (a leading '+' allowed, as in strtod), with its value in
// `value`; "nan" and "inf" count. Values beyond double's range are false (from_chars's
// result_out_of_range).
bool parseDecimal(std::string_view text, double& value);

} // namespace omicron
