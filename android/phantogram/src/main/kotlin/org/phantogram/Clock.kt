package org.phantogram

import android.os.SystemClock

/**
 * The core's clock is the sensor clock: SensorEvent.timestamp, i.e. SystemClock.elapsedRealtimeNanos()
 * (CLOCK_BOOTTIME). Choreographer frame times and MotionEvent times are on CLOCK_MONOTONIC
 * (System.nanoTime, SystemClock.uptimeMillis); the two differ by the time spent in deep sleep,
 * so the offset is read fresh for each conversion.
 */
object Clock {
    fun monotonicToSensorNs(monotonicNs: Long): Long =
        monotonicNs + (SystemClock.elapsedRealtimeNanos() - System.nanoTime())
}
