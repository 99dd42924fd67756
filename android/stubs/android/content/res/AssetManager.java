// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content.res; public final class AssetManager { public String[] list(String path) throws java.io.IOException { return null; } public java.io.InputStream open(String name) throws java.io.IOException { return null; } }
