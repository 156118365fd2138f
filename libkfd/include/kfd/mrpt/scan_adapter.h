// Conversion between MRPT's CObservation2DRangeScan and kfd's core Scan.
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// Geometry (beam count, aperture, direction) of an MRPT scan.
ScanGeometry geometryOf(const mrpt::obs::CObservation2DRangeScan& obs);

/// Copies ranges, validity, intensities (when the scan has them), geometry and timestamp into `out`
/// (buffers reused, no allocation once sized). Odometry is left as it is.
void toCore(const mrpt::obs::CObservation2DRangeScan& obs, Scan& out);

}  // namespace kfd
