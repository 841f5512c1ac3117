// The option groups the commands share, one header each under options/.
#pragma once

#include "options/area_lights.h"
#include "options/bus.h"
#include "options/common.h"
#include "options/connect.h"
#include "options/device.h"
#include "options/grid.h"
#include "options/noise_rule.h"
#include "options/scene.h"
#include "options/server.h"
#include "options/token.h"
#include "options/tracer.h"
#include "options/tracing.h"
