// A map edit from Java, signed as docs/PROTOCOL.md ("Authenticated edits") says: HMAC-SHA256
// (javax.crypto) keyed by the server's control token over the edit's canonical bytes, so the
// token itself never goes on the network. Prints the acknowledgement.
//
//   java -cp /usr/share/java/lcm.jar:/usr/local/share/java/lcmtypes_octomap_rt.jar:octomap_rt_java_examples.jar \
//        MapEdit URL TOKEN free|free-include-unknown|unknown X0 Y0 Z0 X1 Y1 Z1
//   java ... MapEdit URL TOKEN reset
//   (OCTOMAP_RT_NAMESPACE=NS: the server's --namespace; the edit, its MAC and its reply channel are NS's)
//   java ... MapEdit --mac-of TOKEN UTIME REQUEST_ID NONCE OP FLAGS X0 Y0 Z0 X1 Y1 Z1 CLIENT REPLY_CHANNEL
//        (prints the MAC in hex: the test vector of docs/PROTOCOL.md)
import java.io.ByteArrayOutputStream;
import java.io.DataOutputStream;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.security.SecureRandom;

import javax.crypto.Mac;
import javax.crypto.spec.SecretKeySpec;

import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;
import octomap_rt.map_edit_ack_t;
import octomap_rt.map_edit_t;

public class MapEdit implements LCMSubscriber {
  static final String CHANNEL = ProtocolTable.MAP_EDIT_CHANNEL;
  private final long requestId;
  private map_edit_ack_t ack = null;

  MapEdit(long requestId) { this.requestId = requestId; }

  static void putString(DataOutputStream out, String s) throws IOException {
    byte[] b = s.getBytes(StandardCharsets.UTF_8);
    out.writeInt(b.length);
    out.write(b);
  }

  // The canonical bytes of docs/PROTOCOL.md; DataOutputStream writes big-endian.
  static byte[] macInput(String channel, map_edit_t e) throws IOException {
    ByteArrayOutputStream bytes = new ByteArrayOutputStream();
    DataOutputStream out = new DataOutputStream(bytes);
    out.write("octomap-rt map_edit_t v1".getBytes(StandardCharsets.US_ASCII));
    out.writeByte(0);
    putString(out, channel);
    out.writeLong(e.utime);
    out.writeLong(e.request_id);
    out.writeLong(e.nonce);
    out.writeByte(e.op);
    out.writeByte(e.flags);
    for (double d : e.box_min) out.writeDouble(d);
    for (double d : e.box_max) out.writeDouble(d);
    putString(out, e.client_id);
    putString(out, e.reply_channel);
    return bytes.toByteArray();
  }

  static void sign(map_edit_t e, String token, String channel) throws Exception {
    Mac mac = Mac.getInstance("HmacSHA256");
    mac.init(new SecretKeySpec(token.getBytes(StandardCharsets.UTF_8), "HmacSHA256"));
    e.mac = mac.doFinal(macInput(channel, e));
  }

  @Override
  public synchronized void messageReceived(LCM lcm, String channel, LCMDataInputStream in) {
    try {
      map_edit_ack_t a = new map_edit_ack_t(in);
      if (a.request_id != requestId) return;
      ack = a;
      notifyAll();
    } catch (IOException e) {
      System.err.println(channel + ": " + e.getMessage());
    }
  }

  synchronized map_edit_ack_t await(long timeoutMs) throws InterruptedException {
    long end = System.currentTimeMillis() + timeoutMs;
    while (ack == null && System.currentTimeMillis() < end) wait(Math.max(1, end - System.currentTimeMillis()));
    return ack;
  }

  static map_edit_t box(map_edit_t e, String[] a, int from) {
    for (int i = 0; i < 3; ++i) {
      e.box_min[i] = Double.parseDouble(a[from + i]);
      e.box_max[i] = Double.parseDouble(a[from + 3 + i]);
    }
    return e;
  }

  public static void main(String[] args) throws Exception {
    map_edit_t e = new map_edit_t();
    if (args.length == 15 && args[0].equals("--mac-of")) {
      e.utime = Long.parseLong(args[2]);
      e.request_id = Long.parseLong(args[3]);
      e.nonce = Long.parseLong(args[4]);
      e.op = Byte.parseByte(args[5]);
      e.flags = Byte.parseByte(args[6]);
      box(e, args, 7);
      e.client_id = args[13];
      e.reply_channel = args[14];
      sign(e, args[1], CHANNEL);
      StringBuilder hex = new StringBuilder();
      for (byte b : e.mac) hex.append(String.format("%02x", b));
      System.out.println(hex);
      return;
    }
    if (args.length != 3 && args.length != 9) {
      System.err.println("usage: MapEdit URL TOKEN free|free-include-unknown|unknown X0 Y0 Z0 X1 Y1 Z1 | URL TOKEN reset");
      System.exit(1);
    }
    String kind = args[2];
    e.op = kind.equals("reset") ? map_edit_t.OP_RESET
                                : kind.equals("unknown") ? map_edit_t.OP_CLEAR_TO_UNKNOWN : map_edit_t.OP_CLEAR_TO_FREE;
    e.flags = kind.equals("free-include-unknown") ? map_edit_t.FLAG_INCLUDE_UNKNOWN : 0;
    if (e.op != map_edit_t.OP_RESET) box(e, args, 3);
    e.utime = System.currentTimeMillis() * 1000;
    e.request_id = e.utime;
    e.nonce = new SecureRandom().nextLong();
    e.client_id = "java-" + ProcessHandle.current().pid();
    String channel = StatusListener.inNamespace(CHANNEL);
    e.reply_channel =
        StatusListener.inNamespace(ProtocolTable.QUERY_REPLY_PREFIX + e.client_id.toUpperCase().replace('-', '_'));
    sign(e, args[1], channel);  // the MAC covers the channel: an edit for one namespace is refused in another
    LCM lcm = new LCM(args[0]);
    MapEdit waiter = new MapEdit(e.request_id);
    lcm.subscribe(e.reply_channel, waiter);
    lcm.publish(channel, e);
    map_edit_ack_t a = waiter.await(10000);
    lcm.close();
    if (a == null) {
      System.err.println("no acknowledgement within 10 s: is octomap-rt-server running with this LCM URL?");
      System.exit(2);
    }
    System.out.printf("status %d, map state %d%s%n", a.status, a.snapshot_id, a.error.isEmpty() ? "" : ": " + a.error);
    System.exit(a.status == 0 ? 0 : 3);
  }
}
