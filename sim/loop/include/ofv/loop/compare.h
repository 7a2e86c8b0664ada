/**
 * \file compare.h
 * \brief Comparing settings in closed loop: scenario set x settings grid x
 *        seeds, run as independent episodes (parallel, sharded, resumable),
 *        then aggregated into tables and plots.
 *
 * One header per step, in the order a comparison goes through them:
 * grid.h (the variants), sweep.h (planning, shards, running),
 * episode_store.h (the episode files, resume, merge), statistics.h
 * (grouping, intervals), reports.h (tables) and plots.h.
 */
#pragma once

#include "ofv/loop/episode_store.h"
#include "ofv/loop/grid.h"
#include "ofv/loop/plots.h"
#include "ofv/loop/reports.h"
#include "ofv/loop/statistics.h"
#include "ofv/loop/sweep.h"
