// octomap-rt-server's status from Java: lcm.jar (Debian's liblcm-java) and our types jar
// (lcmtypes_octomap_rt.jar, installed in <prefix>/share/java) on the class path, then
// subscribe and decode like any LCM type.
//
//   java -cp /usr/share/java/lcm.jar:/usr/local/share/java/lcmtypes_octomap_rt.jar:octomap_rt_java_examples.jar \
//        StatusListener [URL] [COUNT]       (OCTOMAP_RT_NAMESPACE=NS: the server's --namespace)
import java.io.IOException;

import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;
import octomap_rt.robot_stats_t;
import octomap_rt.server_status_t;

public class StatusListener implements LCMSubscriber {
  private final int wanted;
  private int received = 0;

  StatusListener(int wanted) { this.wanted = wanted; }

  @Override
  public synchronized void messageReceived(LCM lcm, String channel, LCMDataInputStream in) {
    try {
      server_status_t s = new server_status_t(in);
      System.out.printf("%s: state %d (%s), %d scans applied, %.1f scans/s%n", s.server_id, s.state, s.message,
                        s.scans_applied, s.scans_per_s);
      for (robot_stats_t r : s.robots)
        System.out.printf("  robot %s: received %d, applied %d, rejected %d%n", r.robot_id, r.scans_received,
                          r.scans_applied, r.scans_rejected);
      System.out.flush();
      ++received;
      notifyAll();
    } catch (IOException e) {  // not a server_status_t (another version of the types?)
      System.err.println(channel + ": " + e.getMessage());
    }
  }

  synchronized void awaitAll() throws InterruptedException {
    while (wanted == 0 || received < wanted) wait();
  }

  // The server's namespace (its --namespace) from $OCTOMAP_RT_NAMESPACE: NS_ + the name, or the
  // name itself without one (docs/PROTOCOL.md, "The protocol's home").
  static String inNamespace(String name) {
    String ns = System.getenv(ProtocolTable.NAMESPACE_ENV);
    return ns == null || ns.isEmpty() ? name : ns + "_" + name;
  }

  public static void main(String[] args) throws Exception {
    String url = args.length > 0 ? args[0] : ProtocolTable.DEFAULT_LCM_URL;
    int count = args.length > 1 ? Integer.parseInt(args[1]) : 0;
    LCM lcm = new LCM(url);
    StatusListener listener = new StatusListener(count);
    lcm.subscribe(inNamespace(ProtocolTable.STATUS_CHANNEL), listener);
    listener.awaitAll();
    lcm.close();
  }
}
