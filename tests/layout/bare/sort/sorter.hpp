// Fixture: an include without its folder.
#pragma once
#include "sorter_impl.hpp"
