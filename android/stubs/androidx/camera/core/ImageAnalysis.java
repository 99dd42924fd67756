// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.core; public final class ImageAnalysis extends UseCase {
  public static final int STRATEGY_KEEP_ONLY_LATEST = 0; public static final int OUTPUT_IMAGE_FORMAT_YUV_420_888 = 1;
  public interface Analyzer { void analyze(ImageProxy image); }
  public void setAnalyzer(java.util.concurrent.Executor e, Analyzer a) {}
  public static final class Builder implements ExtendableBuilder<ImageAnalysis> { public Builder setBackpressureStrategy(int s) { return this; } public Builder setOutputImageFormat(int f) { return this; } public ImageAnalysis build() { return null; } } }
