// Fixture: a folder the rules do not know.
#pragma once
#include <vector>
