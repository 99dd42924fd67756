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
import androidx.camera.core.CameraInfo
import androidx.camera.core.CameraSelector
import androidx.camera.core.ConcurrentCamera
import androidx.camera.core.ImageAnalysis
import androidx.camera.core.ImageProxy
import androidx.camera.core.UseCaseGroup
import androidx.camera.lifecycle.ProcessCameraProvider
import androidx.core.content.ContextCompat
import androidx.lifecycle.LifecycleOwner
import java.util.concurrent.Executors

/**
 * Camera frames through CameraX image analysis: the front camera's, and the rear camera's too
 * while the core asks for it (`setRear`: the room light is on) where the device runs both at once
 * (CameraX's concurrent cameras, Android 11 and later, on devices that list a front + back
 * pair): the three YUV_420_888 planes as they are (the face
 * tracker reads the front luma, the room light converts to colour in the core), their rotation to
 * upright, the intrinsics, and the capture time, handed to the core with the camera they came
 * from; the core works on its own threads and keeps only the newest frame of each camera. Each
 * frame's exposure (time, ISO, aperture) comes in its Camera2 capture result, forwarded with its
 * time stamp; the core matches the two.
 *
 * Intrinsics: each camera's Camera2 characteristics (active and pre-correction arrays, pixel
 * array, physical size, focal length, LENS_INTRINSIC_CALIBRATION where published) are read once
 * and forwarded as they are; the core derives the intrinsics of each image size from them
 * (`NativeBridge.nativeCameraIntrinsics`, core/src/camera/android.rs), so no camera maths lives
 * here.
 */
class CameraForwarder(private val context: Context, private val engine: () -> Long) {
    private val front = Stream(NativeBridge.CAMERA_FRONT)
    private val rear = Stream(NativeBridge.CAMERA_REAR)
    // Main thread only: what start was given, the provider once CameraX has it, and whether the
    // rear camera is wanted (the core asks for it while the room light is on).
    private var owner: LifecycleOwner? = null
    private var provider: ProcessCameraProvider? = null
    private var withRear = false
    private var rearBound = false

    /** Camera2's characteristics as reported; see NativeBridge.nativeCameraIntrinsics. */
    private class Lens(
        val activeArray: IntArray, val preCorrection: IntArray?, val pixelArray: IntArray?,
        val physicalSizeMm: FloatArray?, val focalLengthMm: Float, val calibration: FloatArray?
    )

    /** Starts the front camera, and the rear one beside it if `withRear` where the device can
     *  (main thread). */
    fun start(owner: LifecycleOwner, withRear: Boolean) {
        this.owner = owner
        this.withRear = withRear
        val future = ProcessCameraProvider.getInstance(context)
        future.addListener(Runnable {
            provider = future.get()
            bind()
        }, ContextCompat.getMainExecutor(context))
    }

    /** Runs the rear camera beside the front one (where the device can) or stops it, binding
     *  the cameras again; the face tracker misses a few frames (main thread). */
    fun setRear(on: Boolean) {
        if (on == withRear) return
        withRear = on
        if (provider != null && (on || rearBound)) bind()
    }

    @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
    private fun bind() {
        val provider = provider ?: return
        val owner = owner ?: return
        provider.unbindAll()
        rearBound = withRear && bindBoth(provider, owner)
        if (rearBound) return
        val camera = provider.bindToLifecycle(owner, CameraSelector.DEFAULT_FRONT_CAMERA, front.analysis())
        front.lens = readLens(Camera2CameraInfo.from(camera.cameraInfo))
    }

    /** Binds the front and the rear camera at once where the device lists such a pair; false
     * (nothing bound) where it does not or the binding fails. */
    @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
    private fun bindBoth(provider: ProcessCameraProvider, owner: LifecycleOwner): Boolean {
        val pair = provider.availableConcurrentCameraInfos.firstOrNull { infos ->
            infos.any { it.lensFacing == CameraSelector.LENS_FACING_FRONT } &&
                infos.any { it.lensFacing == CameraSelector.LENS_FACING_BACK }
        } ?: return false
        val selector = { facing: Int -> pair.first { it.lensFacing == facing }.cameraSelector }
        val config = { facing: Int, stream: Stream ->
            ConcurrentCamera.SingleCameraConfig(
                selector(facing), UseCaseGroup.Builder().addUseCase(stream.analysis()).build(), owner
            )
        }
        val both = try {
            provider.bindToLifecycle(
                listOf(config(CameraSelector.LENS_FACING_FRONT, front), config(CameraSelector.LENS_FACING_BACK, rear))
            )
        } catch (e: RuntimeException) {
            // IllegalArgumentException / UnsupportedOperationException: the pair cannot stream
            // with these use cases after all; the front camera alone still can.
            android.util.Log.w("Phantogram", "front and rear cameras at once: not here; front only", e)
            provider.unbindAll()
            return false
        }
        for (camera in both.cameras) {
            val info: CameraInfo = camera.cameraInfo
            val lens = readLens(Camera2CameraInfo.from(info))
            when (info.lensFacing) {
                CameraSelector.LENS_FACING_FRONT -> front.lens = lens
                CameraSelector.LENS_FACING_BACK -> rear.lens = lens
            }
        }
        return true
    }

    fun close() {
        front.executor.shutdown()
        rear.executor.shutdown()
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

    /** One camera's analysis stream: its own thread, lens, intrinsics and exposures. */
    private inner class Stream(private val camera: Int) {
        val executor = Executors.newSingleThreadExecutor()
        @Volatile var lens: Lens? = null
        // The intrinsics of the last image size seen: [width, height, fx, fy, cx, cy].
        private var intrinsics: FloatArray? = null

        /** A new analysis use case forwarding this camera's frames and exposures. */
        @androidx.annotation.OptIn(markerClass = [ExperimentalCamera2Interop::class])
        fun analysis(): ImageAnalysis {
            val builder = ImageAnalysis.Builder()
                .setBackpressureStrategy(ImageAnalysis.STRATEGY_KEEP_ONLY_LATEST)
                .setOutputImageFormat(ImageAnalysis.OUTPUT_IMAGE_FORMAT_YUV_420_888)
            Camera2Interop.Extender(builder).setSessionCaptureCallback(exposures)
            val analysis = builder.build()
            analysis.setAnalyzer(executor, ImageAnalysis.Analyzer { image -> forward(image) })
            return analysis
        }

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
                // The front and rear lenses differ in aperture; NaN where not reported.
                val aperture = result.get(CaptureResult.LENS_APERTURE) ?: Float.NaN
                try {
                    NativeBridge.nativeCameraExposure(e, camera, time, exposure, iso, aperture)
                } catch (t: RuntimeException) {
                    android.util.Log.e("Phantogram", "camera exposure", t)
                }
            }
        }

        /** [fx, fy, cx, cy] of a width × height image, from the core; null when the camera's
         * characteristics give none (its frames are then not used, and that is said once). */
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
                android.util.Log.e("Phantogram", "no intrinsics for camera $camera: its frames are not used", e)
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
                    e, camera, plane.buffer, image.width, image.height, plane.rowStride,
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
}
