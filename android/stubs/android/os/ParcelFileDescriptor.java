// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.os; public class ParcelFileDescriptor implements java.io.Closeable { public int detachFd() { return -1; } public void close() throws java.io.IOException {} }
