package org.phantogram

import android.content.Context
import android.hardware.camera2.CameraCaptureSession
import android.hardware.camera2.CameraCharacteristics
import android.hardware.camera2.CaptureRequest
import android.hardware.camera2.CaptureResult
import android.hardware.camera2.TotalCaptureResult
import androidx.camera.camera2.interop.Camera2CameraInfo
import androidx.camera.camera2.interop.Camera2Interop
import androidx.camera.camera2.interop.ExperimentalCamera2Interop
import androidx.camera.core.CameraSelector
import androidx.camera.core.ImageAnalysis
import androidx.camera.core.ImageProxy
import androidx.camera.lifecycle.ProcessCameraProvider
import androidx.core.content.ContextCompat
import androidx.lifecycle.LifecycleOwner
import java.util.concurrent.Executors

/**
 * Front-camera frames through CameraX image analysis: the three YUV_420_888 planes as they are
 * (the face tracker reads the luma, the room light converts to colour in the core), their
 * rotation to upright, the intrinsics, and the capture time, handed to the core, which works on
 * its own threads and keeps only the newest frame. Each frame's exposure (time and ISO) comes in
 * its Camera2 capture result, forwarded with its time stamp; the core matches the two.
 *
 * Intrinsics: the camera's Camera2 characteristics (active and pre-correction arrays, pixel
 * array, physical size, focal length, LENS_INTRINSIC_CALIBRATION where published) are read once
 * and forwarded as they are; the core derives the intrinsics of each image size from them
 * (`NativeBridge.nativeCameraIntrinsics`, core/src/camera/android.rs), so no camera maths lives
 * here.
 */
class CameraForwarder(private val context: Context, private val engine: () -> Long) {
    private val executor = Executors.newSingleThreadExecutor()
    private var lens: Lens? = null
    // The intrinsics of the last image size seen: [width, height, fx, fy, cx, cy].
    private var intrinsics: FloatArray? = null

    /** Camera2's characteristics as reported; see NativeBridge.nativeCameraIntrinsics. */
    private class Lens(
        val activeArray: IntArray, val preCorrection: IntArray?, val pixelArray: IntArray?,
        val physicalSizeMm: FloatArray?, val focalLengthMm: Float, val calibration: FloatArray?
    )

    @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
    fun start(owner: LifecycleOwner) {
        val future = ProcessCameraProvider.getInstance(context)
        future.addListener(Runnable {
            val provider = future.get()
            val builder = ImageAnalysis.Builder()
                .setBackpressureStrategy(ImageAnalysis.STRATEGY_KEEP_ONLY_LATEST)
                .setOutputImageFormat(ImageAnalysis.OUTPUT_IMAGE_FORMAT_YUV_420_888)
            Camera2Interop.Extender(builder).setSessionCaptureCallback(exposures)
            val analysis = builder.build()
            analysis.setAnalyzer(executor, ImageAnalysis.Analyzer { image -> forward(image) })
            provider.unbindAll()
            val camera = provider.bindToLifecycle(owner, CameraSelector.DEFAULT_FRONT_CAMERA, analysis)
            lens = readLens(Camera2CameraInfo.from(camera.cameraInfo))
        }, ContextCompat.getMainExecutor(context))
    }

    fun close() = executor.shutdown()

    /** Each capture's exposure, by its sensor time stamp (= the image's), to the core. */
    private val exposures = object : CameraCaptureSession.CaptureCallback() {
        override fun onCaptureCompleted(
            session: CameraCaptureSession, request: CaptureRequest, result: TotalCaptureResult
        ) {
            val e = engine()
            if (e == 0L) return
            val time = result.get(CaptureResult.SENSOR_TIMESTAMP) ?: return
            val exposure = result.get(CaptureResult.SENSOR_EXPOSURE_TIME) ?: return
            val iso = result.get(CaptureResult.SENSOR_SENSITIVITY) ?: return
            try {
                NativeBridge.nativeCameraExposure(e, time, exposure, iso)
            } catch (t: RuntimeException) {
                android.util.Log.e("Phantogram", "camera exposure", t)
            }
        }
    }

    @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
    private fun readLens(info: Camera2CameraInfo): Lens? {
        val active = info.getCameraCharacteristic(CameraCharacteristics.SENSOR_INFO_ACTIVE_ARRAY_SIZE) ?: return null
        val pre = info.getCameraCharacteristic(CameraCharacteristics.SENSOR_INFO_PRE_CORRECTION_ACTIVE_ARRAY_SIZE)
        val pixels = info.getCameraCharacteristic(CameraCharacteristics.SENSOR_INFO_PIXEL_ARRAY_SIZE)
        val physical = info.getCameraCharacteristic(CameraCharacteristics.SENSOR_INFO_PHYSICAL_SIZE)
        val focal = info.getCameraCharacteristic(CameraCharacteristics.LENS_INFO_AVAILABLE_FOCAL_LENGTHS)
        return Lens(
            intArrayOf(active.left, active.top, active.right, active.bottom),
            pre?.let { intArrayOf(it.left, it.top, it.right, it.bottom) },
            pixels?.let { intArrayOf(it.width, it.height) },
            physical?.let { floatArrayOf(it.width, it.height) },
            if (focal != null && focal.isNotEmpty()) focal[0] else Float.NaN,
            info.getCameraCharacteristic(CameraCharacteristics.LENS_INTRINSIC_CALIBRATION)
        )
    }

    /** [fx, fy, cx, cy] of a width × height image, from the core; null when the camera's
     * characteristics give none (face tracking then stays off, and says why once). */
    private fun intrinsicsFor(width: Int, height: Int): FloatArray? {
        val cached = intrinsics
        if (cached != null && cached[0] == width.toFloat() && cached[1] == height.toFloat()) {
            return cached.copyOfRange(2, 6)
        }
        val l = lens ?: return null
        return try {
            val k = NativeBridge.nativeCameraIntrinsics(
                l.activeArray, l.preCorrection, l.pixelArray, l.physicalSizeMm, l.focalLengthMm, l.calibration,
                width, height
            )
            intrinsics = floatArrayOf(width.toFloat(), height.toFloat(), k[0], k[1], k[2], k[3])
            k
        } catch (e: IllegalArgumentException) {
            android.util.Log.e("Phantogram", "no camera intrinsics: face tracking is off", e)
            lens = null
            null
        }
    }

    private fun forward(image: ImageProxy) {
        try {
            val e = engine()
            if (e == 0L) return
            val planes = image.planes
            val plane = planes[0]
            if (plane.pixelStride != 1) return
            val k = intrinsicsFor(image.width, image.height) ?: return
            // YUV_420_888's chroma planes share their row and pixel strides.
            val colour = planes.size >= 3
            NativeBridge.nativeCameraFrame(
                e, plane.buffer, image.width, image.height, plane.rowStride,
                if (colour) planes[1].buffer else null, if (colour) planes[2].buffer else null,
                if (colour) planes[1].rowStride else 0, if (colour) planes[1].pixelStride else 0,
                image.imageInfo.rotationDegrees,
                k[0], k[1], k[2], k[3],
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
