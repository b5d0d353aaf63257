// <regex> for the tests, without GCC 12's false maybe-uninitialized warnings inside libstdc++'s
// regex automaton, which appear at -O2 with -fsanitize=address and which -Werror would turn
// into a failed ASan build of the test programs.
#pragma once

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <regex>
#pragma GCC diagnostic pop
