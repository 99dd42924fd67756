import CoreMotion
import PhantogramCore

/// Raw accelerometer and gyroscope at 200 Hz with their own time stamps, the *calibrated*
/// magnetic field (device motion's `magneticField`: Core Motion's hard-iron calibration removes
/// the phone's own magnetisation, which the raw `CMMagnetometerData` still holds and which would
/// turn the heading), and Core Motion's fused attitude for comparison, pushed to the core from a
/// background queue.
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
        if manager.isDeviceMotionAvailable,
           CMMotionManager.availableAttitudeReferenceFrames().contains(.xMagneticNorthZVertical) {
            // A magnetic reference frame makes Core Motion calibrate the magnetometer.
            manager.deviceMotionUpdateInterval = 1.0 / 50.0
            manager.startDeviceMotionUpdates(using: .xMagneticNorthZVertical, to: queue) { motion, _ in
                guard let m = motion else { return }
                let q = m.attitude.quaternion
                pg_push_device_motion(h, m.timestamp, q.w, q.x, q.y, q.z)
                // Until the calibration has converged (a figure-eight motion speeds it up) the
                // field is withheld: the fusion then runs on gravity and the gyroscope alone,
                // which is better than a heading pulled by the phone's own bias.
                let field = m.magneticField
                if field.accuracy != .uncalibrated {
                    pg_push_magnetometer(h, m.timestamp, field.field.x, field.field.y, field.field.z)
                }
            }
        } else if manager.isMagnetometerAvailable {
            // No magnetic reference frame on this device: the raw field is all there is.
            manager.magnetometerUpdateInterval = 1.0 / 50.0
            manager.startMagnetometerUpdates(to: queue) { data, _ in
                guard let d = data else { return }
                pg_push_magnetometer(h, d.timestamp, d.magneticField.x, d.magneticField.y, d.magneticField.z)
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
