import CoreMotion
import PhantogramCore

/// Raw accelerometer, gyroscope and magnetometer at 100–200 Hz with their own time stamps, and
/// Core Motion's fused attitude for comparison, pushed to the core from a background queue.
final class MotionSource {
    private let manager = CMMotionManager()
    private let queue: OperationQueue = {
        let q = OperationQueue()
        q.name = "phantogram-motion"
        q.maxConcurrentOperationCount = 1
        return q
    }()
    private let engine: Engine

    init(engine: Engine) { self.engine = engine }

    func start() {
        let h = engine.handle
        let interval = 1.0 / 200.0
        if manager.isAccelerometerAvailable {
            manager.accelerometerUpdateInterval = interval
            manager.startAccelerometerUpdates(to: queue) { data, _ in
                guard let d = data else { return }
                pg_push_accelerometer(h, d.timestamp, d.acceleration.x, d.acceleration.y, d.acceleration.z)
            }
        }
        if manager.isGyroAvailable {
            manager.gyroUpdateInterval = interval
            manager.startGyroUpdates(to: queue) { data, _ in
                guard let d = data else { return }
                pg_push_gyroscope(h, d.timestamp, d.rotationRate.x, d.rotationRate.y, d.rotationRate.z)
            }
        }
        if manager.isMagnetometerAvailable {
            manager.magnetometerUpdateInterval = 1.0 / 50.0
            manager.startMagnetometerUpdates(to: queue) { data, _ in
                guard let d = data else { return }
                pg_push_magnetometer(h, d.timestamp, d.magneticField.x, d.magneticField.y, d.magneticField.z)
            }
        }
        if manager.isDeviceMotionAvailable,
           CMMotionManager.availableAttitudeReferenceFrames().contains(.xMagneticNorthZVertical) {
            manager.deviceMotionUpdateInterval = 1.0 / 50.0
            manager.startDeviceMotionUpdates(using: .xMagneticNorthZVertical, to: queue) { motion, _ in
                guard let m = motion else { return }
                let q = m.attitude.quaternion
                pg_push_device_motion(h, m.timestamp, q.w, q.x, q.y, q.z)
            }
        }
    }

    func stop() {
        manager.stopAccelerometerUpdates()
        manager.stopGyroUpdates()
        manager.stopMagnetometerUpdates()
        manager.stopDeviceMotionUpdates()
    }
}
