// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.core; public final class UseCaseGroup { public static final class Builder { public Builder addUseCase(UseCase u) { return this; } public UseCaseGroup build() { return new UseCaseGroup(); } } }
