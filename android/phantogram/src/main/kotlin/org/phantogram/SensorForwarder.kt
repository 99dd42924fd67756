package org.phantogram

import android.hardware.Sensor
import android.hardware.SensorEvent
import android.hardware.SensorEventListener
import android.hardware.SensorManager
import android.os.Handler
import android.os.HandlerThread

/**
 * Forwards the raw accelerometer, gyroscope and magnetometer (and the platform rotation vector,
 * for comparison) with their own time stamps, at 200 Hz (the fastest rate apps get without the
 * HIGH_SAMPLING_RATE_SENSORS permission), on a thread of its own. Missing sensors are simply not
 * registered: the core falls back (no gyroscope → low-pass, no magnetometer → 6-D).
 */
class SensorForwarder(private val manager: SensorManager, private val engine: () -> Long) : SensorEventListener {
    private val thread = HandlerThread("phantogram-sensors").apply { start() }
    private val handler = Handler(thread.looper)
    /** Sensor.getMaximumRange() of the accelerometer and gyroscope (0: missing), told to each new
     *  engine once, from the sensor thread, before its first reading. */
    @Volatile private var accelRange = 0f
    @Volatile private var gyroRange = 0f
    private var rangesToldTo = 0L
    private val types = intArrayOf(
        Sensor.TYPE_ACCELEROMETER,
        Sensor.TYPE_GYROSCOPE,
        Sensor.TYPE_MAGNETIC_FIELD,
        Sensor.TYPE_ROTATION_VECTOR
    )

    fun start() {
        val sensors = types.map { manager.getDefaultSensor(it) }.filterNotNull()
        // Both ranges are known before the first reading can arrive.
        accelRange = sensors.firstOrNull { it.type == Sensor.TYPE_ACCELEROMETER }?.maximumRange ?: 0f
        gyroRange = sensors.firstOrNull { it.type == Sensor.TYPE_GYROSCOPE }?.maximumRange ?: 0f
        for (sensor in sensors) {
            manager.registerListener(this, sensor, SAMPLING_PERIOD_US, handler)
        }
    }

    fun stop() = manager.unregisterListener(this)

    fun close() {
        stop()
        thread.quitSafely()
    }

    override fun onSensorChanged(event: SensorEvent) {
        val e = engine()
        if (e == 0L) return
        if (e != rangesToldTo) {
            // Clipped readings are then known from the first one (the core learns them otherwise).
            NativeBridge.nativeSetSensorRanges(e, accelRange, gyroRange)
            rangesToldTo = e
        }
        val v = event.values
        val w = if (v.size >= 4) v[3] else Float.NaN
        // Rejected samples (NaN, repeated time stamps) return false and are counted by the core.
        NativeBridge.nativePushSensor(e, event.sensor.type, event.timestamp, v[0], v[1], v[2], w)
    }

    override fun onAccuracyChanged(sensor: Sensor, accuracy: Int) {}

    private companion object {
        const val SAMPLING_PERIOD_US = 5_000
    }
}
