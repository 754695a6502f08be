// The float grid of a .vdb file, read behind the checks of vdb_layout.h and under the allocation
// cap of allocation_cap.h: the one way frepfarm hands a file to OpenVDB's reader (frep mesh's
// reader and frVolume's field). Defined in vdb_reader.cpp; include only where OpenVDB already is.
#pragma once

#include <openvdb/openvdb.h>

#include <string>

#include "vdb_layout.h"

namespace frep::io {

struct GridRequest {
  std::string shown;       // the file's name in messages (a job's file is read from a temporary copy)
  std::string gridName;    // empty: the first float grid
  std::string nameSource;  // where a grid name comes from, for messages ("-o/--object")
  std::string verb;        // what the grid is for ("mesh")
  std::string user;        // who needs a float grid ("frep mesh")
};

struct CheckedGrid {
  openvdb::FloatGrid::Ptr grid;  // never null
  VdbLayout layout;
};

// Throws Error: exit 3 (kExitIoError) for a file that is damaged, truncated or not a VDB, exit 1
// (kExitModelError) when the grid asked for is missing or not a float grid; messages name
// `request.shown` and list the file's grids.
CheckedGrid readCheckedFloatGrid(const std::string& path, const GridRequest& request);

}  // namespace frep::io
