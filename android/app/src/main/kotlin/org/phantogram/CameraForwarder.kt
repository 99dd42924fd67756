package org.phantogram

import android.content.Context
import android.hardware.camera2.CameraCharacteristics
import androidx.camera.camera2.interop.Camera2CameraInfo
import androidx.camera.camera2.interop.ExperimentalCamera2Interop
import androidx.camera.core.CameraSelector
import androidx.camera.core.ImageAnalysis
import androidx.camera.core.ImageProxy
import androidx.camera.lifecycle.ProcessCameraProvider
import androidx.core.content.ContextCompat
import androidx.lifecycle.LifecycleOwner
import java.util.concurrent.Executors

/**
 * Front-camera frames through CameraX image analysis: the luma plane (YUV_420_888 plane 0),
 * its rotation to upright, the intrinsics, and the capture time, handed to the core, which
 * tracks the face on its own thread and keeps only the newest frame.
 *
 * Intrinsics: LENS_INTRINSIC_CALIBRATION (fx, fy, cx, cy in active-array pixels) where the
 * device publishes it, else the focal length and the physical sensor size; both scaled to the
 * analysis image, assumed to span the active array's width with the height cropped centrally
 * (CameraX's default for a 4:3 analysis stream on a 4:3 sensor, where the crop is nil).
 */
class CameraForwarder(private val context: Context, private val engine: () -> Long) {
    private val executor = Executors.newSingleThreadExecutor()
    private var intrinsics: FloatArray? = null // fx, fy, cx, cy in active-array pixels, active width, height

    @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
    fun start(owner: LifecycleOwner) {
        val future = ProcessCameraProvider.getInstance(context)
        future.addListener(Runnable {
            val provider = future.get()
            val analysis = ImageAnalysis.Builder()
                .setBackpressureStrategy(ImageAnalysis.STRATEGY_KEEP_ONLY_LATEST)
                .setOutputImageFormat(ImageAnalysis.OUTPUT_IMAGE_FORMAT_YUV_420_888)
                .build()
            analysis.setAnalyzer(executor, ImageAnalysis.Analyzer { image -> forward(image) })
            provider.unbindAll()
            val camera = provider.bindToLifecycle(owner, CameraSelector.DEFAULT_FRONT_CAMERA, analysis)
            intrinsics = readIntrinsics(Camera2CameraInfo.from(camera.cameraInfo))
        }, ContextCompat.getMainExecutor(context))
    }

    fun close() = executor.shutdown()

    @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
    private fun readIntrinsics(info: Camera2CameraInfo): FloatArray? {
        val active = info.getCameraCharacteristic(CameraCharacteristics.SENSOR_INFO_ACTIVE_ARRAY_SIZE) ?: return null
        val w = active.width().toFloat()
        val h = active.height().toFloat()
        val calibration = info.getCameraCharacteristic(CameraCharacteristics.LENS_INTRINSIC_CALIBRATION)
        if (calibration != null && calibration.size >= 4 && calibration[0] > 0f) {
            return floatArrayOf(calibration[0], calibration[1], calibration[2], calibration[3], w, h)
        }
        val focal = info.getCameraCharacteristic(CameraCharacteristics.LENS_INFO_AVAILABLE_FOCAL_LENGTHS)
        val physical = info.getCameraCharacteristic(CameraCharacteristics.SENSOR_INFO_PHYSICAL_SIZE)
        if (focal == null || focal.isEmpty() || physical == null || physical.width <= 0f) return null
        val f = focal[0] / physical.width * w
        return floatArrayOf(f, f, w / 2, h / 2, w, h)
    }

    private fun forward(image: ImageProxy) {
        try {
            val e = engine()
            val k = intrinsics ?: return
            if (e == 0L) return
            val plane = image.planes[0]
            if (plane.pixelStride != 1) return
            // Scale from the active array to this image (width-matched, height centred).
            val s = image.width / k[4]
            val cropY = (k[5] * s - image.height) / 2
            NativeBridge.nativeCameraFrame(
                e, plane.buffer, image.width, image.height, plane.rowStride, image.imageInfo.rotationDegrees,
                k[0] * s, k[1] * s, k[2] * s, k[3] * s - cropY,
                // CameraX time stamps are on the sensor-time-stamp clock (CLOCK_BOOTTIME on
                // devices reporting SENSOR_INFO_TIMESTAMP_SOURCE_REALTIME, which phones do).
                image.imageInfo.timestamp
            )
        } catch (t: RuntimeException) {
            // A bad frame must not stop the analysis stream; the next one may be fine.
            android.util.Log.e("Phantogram", "camera frame", t)
        } finally {
            image.close()
        }
    }
}
