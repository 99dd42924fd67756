// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package com.google.common.util.concurrent; public interface ListenableFuture<V> extends java.util.concurrent.Future<V> { void addListener(Runnable listener, java.util.concurrent.Executor executor); }
