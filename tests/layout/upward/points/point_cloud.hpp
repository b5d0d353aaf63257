// Fixture: the lowest stage reaching up the pipeline.
#pragma once
#include "build/tree.hpp"
