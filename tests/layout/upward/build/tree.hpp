// Fixture: an allowed include (build may use points).
#pragma once
#include "points/point_cloud.hpp"
