import AVFoundation
import ImageIO
import simd
import PhantogramCore

/// Camera frames (both planes of 4:2:0 bi-planar full-range buffers: the face tracker reads the
/// front camera's luma, the room light converts to colour in the core) with the camera's
/// intrinsic matrix and the exposure from the buffer's EXIF attachment, pushed to the core with
/// the camera they came from, which works on its own threads. The front camera always; the rear
/// one too, for the room light, while the core asks for it (`setRear`: the room light is on) where
/// the device runs both at once (`AVCaptureMultiCamSession`, iPhone XS and later). Without
/// permission the app runs on tilt alone.
final class CameraSource: NSObject, AVCaptureVideoDataOutputSampleBufferDelegate {
    /// Made on `queue` when the camera starts: a multi-camera session where the device has one
    /// for the front and rear cameras, else a plain one for the front camera.
    private var session: AVCaptureSession?
    private let queue = DispatchQueue(label: "phantogram-camera")
    private let engine: Engine
    /// Each output's camera (the core's code: 0 front, 1 rear) and the clockwise turn that makes
    /// its buffers upright in portrait. Written and read on `queue` only.
    private var cameras: [ObjectIdentifier: (code: UInt32, turnCw: UInt32)] = [:]
    /// Whether the rear camera is wanted. Written and read on `queue` only.
    private var withRear: Bool

    private init(engine: Engine, withRear: Bool) {
        self.engine = engine
        self.withRear = withRear
    }

    /// Starts at once when allowed. When the user has not been asked yet, the core's camera page
    /// explains first (`pg_camera_permission_needed`) and the system's request waits for
    /// `requestAccess()`, called when the core asks for it. Returns the source, or nil when the
    /// camera was refused (tilt only).
    static func startIfAllowed(engine: Engine, withRear: Bool) -> CameraSource? {
        let source = CameraSource(engine: engine, withRear: withRear)
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

    /// Runs the rear camera beside the front one (where the device can) or stops it, starting
    /// the session again if it runs; the face tracker misses a few frames.
    func setRear(_ on: Bool) {
        queue.async {
            guard on != self.withRear else { return }
            self.withRear = on
            guard let running = self.session else { return }
            running.stopRunning()
            self.session = nil
            self.cameras.removeAll()
            self.configureAndStart()
        }
    }

    private func configureAndStart() {
        if withRear && AVCaptureMultiCamSession.isMultiCamSupported {
            let multi = AVCaptureMultiCamSession()
            if configureBoth(multi) {
                session = multi
                multi.startRunning()
                return
            }
            cameras.removeAll()
        }
        guard let device = AVCaptureDevice.default(.builtInWideAngleCamera, for: .video, position: .front),
              let input = try? AVCaptureDeviceInput(device: device) else { return }
        let single = AVCaptureSession()
        single.beginConfiguration()
        single.sessionPreset = .vga640x480
        let output = makeOutput()
        guard single.canAddInput(input), single.canAddOutput(output) else { return }
        single.addInput(input)
        single.addOutput(output)
        if let connection = output.connection(with: .video) { configure(connection) }
        // The front camera's buffers are landscape; a quarter turn counter-clockwise (270° cw)
        // makes them upright in portrait.
        cameras[ObjectIdentifier(output)] = (0, 270)
        single.commitConfiguration()
        session = single
        single.startRunning()
    }

    /// The front and rear wide-angle cameras in one multi-camera session, each into its own
    /// output through an explicit connection (as `AVCaptureMultiCamSession` asks). False when
    /// the device cannot run the pair within its hardware and power budget.
    private func configureBoth(_ multi: AVCaptureMultiCamSession) -> Bool {
        multi.beginConfiguration()
        defer { multi.commitConfiguration() }
        // Front buffers: 270° cw to upright (as above); rear buffers are landscape the other way
        // round: a quarter turn clockwise.
        let pairs: [(AVCaptureDevice.Position, UInt32, UInt32)] = [(.front, 0, 270), (.back, 1, 90)]
        for (position, code, turn) in pairs {
            guard let device = AVCaptureDevice.default(.builtInWideAngleCamera, for: .video, position: position),
                  useSmallMultiCamFormat(device),
                  let input = try? AVCaptureDeviceInput(device: device),
                  multi.canAddInput(input) else { return false }
            multi.addInputWithNoConnections(input)
            let output = makeOutput()
            guard multi.canAddOutput(output) else { return false }
            multi.addOutputWithNoConnections(output)
            guard let port = input.ports(for: .video, sourceDeviceType: device.deviceType,
                                         sourceDevicePosition: position).first else { return false }
            let connection = AVCaptureConnection(inputPorts: [port], output: output)
            guard multi.canAddConnection(connection) else { return false }
            multi.addConnection(connection)
            configure(connection)
            cameras[ObjectIdentifier(output)] = (code, turn)
        }
        // Over 1 the session would not run (or would be stopped by the system's pressure).
        return multi.hardwareCost < 1.0 && multi.systemPressureCost < 1.0
    }

    /// The smallest format the device can stream beside another camera that is at least VGA
    /// (what the face tracker wants); false when there is none.
    private func useSmallMultiCamFormat(_ device: AVCaptureDevice) -> Bool {
        let width = { (f: AVCaptureDevice.Format) in CMVideoFormatDescriptionGetDimensions(f.formatDescription).width }
        guard let format = device.formats.filter({ $0.isMultiCamSupported && width($0) >= 640 })
            .min(by: { width($0) < width($1) }),
            (try? device.lockForConfiguration()) != nil else { return false }
        device.activeFormat = format
        device.unlockForConfiguration()
        return true
    }

    private func makeOutput() -> AVCaptureVideoDataOutput {
        let output = AVCaptureVideoDataOutput()
        output.videoSettings = [kCVPixelBufferPixelFormatTypeKey as String: kCVPixelFormatType_420YpCbCr8BiPlanarFullRange]
        output.alwaysDiscardsLateVideoFrames = true
        output.setSampleBufferDelegate(self, queue: queue)
        return output
    }

    private func configure(_ connection: AVCaptureConnection) {
        // Unmirrored sensor-orientation buffers; the core turns them upright itself.
        if connection.isVideoMirroringSupported {
            connection.automaticallyAdjustsVideoMirroring = false
            connection.isVideoMirrored = false
        }
        if connection.isCameraIntrinsicMatrixDeliverySupported {
            connection.isCameraIntrinsicMatrixDeliveryEnabled = true
        }
    }

    func stop() { queue.async { self.session?.stopRunning() } }

    func captureOutput(_ output: AVCaptureOutput, didOutput sampleBuffer: CMSampleBuffer,
                       from connection: AVCaptureConnection) {
        guard let camera = cameras[ObjectIdentifier(output)],
              let pixels = CMSampleBufferGetImageBuffer(sampleBuffer),
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
        // Exposure time (s), ISO and f-number (the two lenses differ) from the EXIF attachment;
        // NaN when the buffer has none.
        let exif = CMGetAttachment(sampleBuffer, key: kCGImagePropertyExifDictionary, attachmentModeOut: nil)
            as? [String: Any]
        let exposureS = (exif?[kCGImagePropertyExifExposureTime as String] as? Double) ?? .nan
        let iso = ((exif?[kCGImagePropertyExifISOSpeedRatings as String] as? [Double])?.first) ?? .nan
        let fNumber = (exif?[kCGImagePropertyExifFNumber as String] as? Double) ?? .nan
        let time = CMTimeGetSeconds(CMSampleBufferGetPresentationTimeStamp(sampleBuffer))
        // Column-major: k[0][0] = fx, k[1][1] = fy, k[2] = (cx, cy).
        pg_camera_frame(engine.handle, camera.code, base.assumingMemoryBound(to: UInt8.self), UInt32(width),
                        UInt32(height), stride, cbcr?.assumingMemoryBound(to: UInt8.self), cbcrStride, camera.turnCw,
                        k[0][0], k[1][1], k[2][0], k[2][1], exposureS, iso, fNumber, time)
    }
}
