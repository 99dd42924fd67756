import AVFoundation
import ImageIO
import simd
import PhantogramCore

/// Front-camera frames (both planes of 4:2:0 bi-planar full-range buffers: the face tracker reads
/// the luma, the room light converts to colour in the core) with the camera's intrinsic matrix
/// and the exposure from the buffer's EXIF attachment, pushed to the core, which works on its own
/// threads. Without permission the app runs on tilt alone.
final class CameraSource: NSObject, AVCaptureVideoDataOutputSampleBufferDelegate {
    private let session = AVCaptureSession()
    private let queue = DispatchQueue(label: "phantogram-camera")
    private let engine: Engine

    private init(engine: Engine) { self.engine = engine }

    /// Starts at once when allowed. When the user has not been asked yet, the core's camera page
    /// explains first (`pg_camera_permission_needed`) and the system's request waits for
    /// `requestAccess()`, called when the core asks for it. Returns the source, or nil when the
    /// camera was refused (tilt only).
    static func startIfAllowed(engine: Engine) -> CameraSource? {
        let source = CameraSource(engine: engine)
        switch AVCaptureDevice.authorizationStatus(for: .video) {
        case .authorized:
            source.queue.async { source.configureAndStart() }
        case .notDetermined:
            _ = pg_camera_permission_needed(engine.handle)
        default:
            return nil
        }
        return source
    }

    /// The system's permission request (the core's camera page has said why); starts when granted.
    func requestAccess() {
        AVCaptureDevice.requestAccess(for: .video) { granted in
            if granted { self.queue.async { self.configureAndStart() } }
        }
    }

    private func configureAndStart() {
        guard let device = AVCaptureDevice.default(.builtInWideAngleCamera, for: .video, position: .front),
              let input = try? AVCaptureDeviceInput(device: device) else { return }
        session.beginConfiguration()
        session.sessionPreset = .vga640x480
        let output = AVCaptureVideoDataOutput()
        output.videoSettings = [kCVPixelBufferPixelFormatTypeKey as String: kCVPixelFormatType_420YpCbCr8BiPlanarFullRange]
        output.alwaysDiscardsLateVideoFrames = true
        output.setSampleBufferDelegate(self, queue: queue)
        guard session.canAddInput(input), session.canAddOutput(output) else { return }
        session.addInput(input)
        session.addOutput(output)
        if let connection = output.connection(with: .video) {
            // Unmirrored sensor-orientation buffers; the core turns them upright itself.
            connection.automaticallyAdjustsVideoMirroring = false
            connection.isVideoMirrored = false
            if connection.isCameraIntrinsicMatrixDeliverySupported {
                connection.isCameraIntrinsicMatrixDeliveryEnabled = true
            }
        }
        session.commitConfiguration()
        session.startRunning()
    }

    func stop() { queue.async { self.session.stopRunning() } }

    func captureOutput(_ output: AVCaptureOutput, didOutput sampleBuffer: CMSampleBuffer,
                       from connection: AVCaptureConnection) {
        guard let pixels = CMSampleBufferGetImageBuffer(sampleBuffer),
              let data = CMGetAttachment(sampleBuffer, key: kCMSampleBufferAttachmentKey_CameraIntrinsicMatrix,
                                         attachmentModeOut: nil) as? Data,
              data.count >= MemoryLayout<matrix_float3x3>.size else { return }
        let k = data.withUnsafeBytes { $0.load(as: matrix_float3x3.self) }
        CVPixelBufferLockBaseAddress(pixels, .readOnly)
        defer { CVPixelBufferUnlockBaseAddress(pixels, .readOnly) }
        guard let base = CVPixelBufferGetBaseAddressOfPlane(pixels, 0) else { return }
        let width = CVPixelBufferGetWidthOfPlane(pixels, 0)
        let height = CVPixelBufferGetHeightOfPlane(pixels, 0)
        let stride = CVPixelBufferGetBytesPerRowOfPlane(pixels, 0)
        // Plane 1 is the interleaved CbCr plane (nil: luma only, the room light is then grey).
        let cbcr = CVPixelBufferGetPlaneCount(pixels) > 1 ? CVPixelBufferGetBaseAddressOfPlane(pixels, 1) : nil
        let cbcrStride = cbcr == nil ? 0 : CVPixelBufferGetBytesPerRowOfPlane(pixels, 1)
        // Exposure time (s) and ISO from the EXIF attachment; NaN when the buffer has none.
        let exif = CMGetAttachment(sampleBuffer, key: kCGImagePropertyExifDictionary, attachmentModeOut: nil)
            as? [String: Any]
        let exposureS = (exif?[kCGImagePropertyExifExposureTime as String] as? Double) ?? .nan
        let iso = ((exif?[kCGImagePropertyExifISOSpeedRatings as String] as? [Double])?.first) ?? .nan
        let time = CMTimeGetSeconds(CMSampleBufferGetPresentationTimeStamp(sampleBuffer))
        // The front camera's buffers are landscape; a quarter turn counter-clockwise (270° cw)
        // makes them upright in portrait. Column-major: k[0][0] = fx, k[1][1] = fy, k[2] = (cx, cy).
        pg_camera_frame(engine.handle, base.assumingMemoryBound(to: UInt8.self), UInt32(width), UInt32(height),
                        stride, cbcr?.assumingMemoryBound(to: UInt8.self), cbcrStride, 270,
                        k[0][0], k[1][1], k[2][0], k[2][1], exposureS, iso, time)
    }
}
