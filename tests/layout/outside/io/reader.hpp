// Fixture: the core reaching into the widget.
#pragma once
#include "widget/cloud_view.hpp"
